// FK-HMD / FK-HSD: forward kinematics, joint angles to tool xyz, bit for bit the
// model's `fk` (tactile-math, kernels.rs, fk_from_trig) in the hybrid arithmetic:
// three TFBs (tfb_sincos) side by side, then f32 products and sums in exactly the
// order Rust evaluates them (left to right, each operation rounded once):
//
//   x = -(s1 * (L2*s3 + L1*c2))
//   y = (-(L2*c3) + L1*s2) + L3
//   z = ((L2*c1)*s3 + (L1*c1)*c2) - L4
//
// One sample a clock, no back-pressure, no reset on the datapath. Stage map (SC the
// latency of tfb_sincos, ITER + 5 in the pipeline "sample"; MUL, ADD the f32 units'
// latencies):
//
//   0 .. SC                 sin, cos of t1, t2, t3   (3 tfb_sincos)
//   SC .. +MUL              L2*s3, L1*c2, L2*c3, L1*s2, L2*c1, L1*c1      (6 f32_mul)
//   SC+MUL .. +ADD          a = L2*s3 + L1*c2; u = -(L2*c3) + L1*s2      (2 f32_add)
//   SC+MUL .. +MUL          (L2*c1)*s3, (L1*c1)*c2    s3, c2 delayed MUL  (2 f32_mul)
//   SC+MUL+ADD .. +MUL      m = s1 * a                s1 delayed MUL+ADD   (f32_mul)
//   SC+MUL+ADD .. +ADD      y = u + L3                                     (f32_add)
//   SC+2MUL .. +ADD         w = (L2*c1)*s3 + (L1*c1)*c2                    (f32_add)
//   SC+2MUL+ADD .. +ADD     z = w - L4                                     (f32_add)
//   x = -m (a sign flip) delayed ADD, y delayed MUL, to meet z.
//
//   LATENCY = (ITER + 5) + 2 F32_MUL_LAT + 2 F32_ADD_LAT (+ PIPE_M)
//
// In the paper's architecture (pipe.vh's PIPE_M = 1: no register inside any unit) every
// output passes one register more, so that a sample takes one clock, of a period as
// long as the whole datapath.
//
// err: OR of the three TFBs' range_err (an angle with |angle| >= 3 pi, inf or NaN; the
// outputs are then NaN), lined up with the outputs. dbg = {s1, c1, s2, c2, s3, c3}
// (s1 in the top 32 bits), lined up with the outputs.
// KIN_MUTANT_FK: z's first product reassociated as L2*(c1*s3), same latency.
module kin_fk (
    input  wire         clk,
    input  wire         in_valid,
    input  wire [31:0]  t1, t2, t3,
    output wire         out_valid,
    output wire [31:0]  x, y, z,
    output wire         err,
    output wire [191:0] dbg
);
    `include "tfb_params.vh"
    `include "kin_params.vh"
    `include "f32_lat.vh"
    `include "f32_fn.vh"

    localparam integer SC = `TFB_SINCOS_LAT(ITER);     // tfb_sincos's LATENCY
    localparam integer MUL = F32_MUL_LAT;
    localparam integer ADD = F32_ADD_LAT;
    localparam integer LATENCY = SC + 2 * MUL + 2 * ADD + PIPE_M;

    // ---- 0 .. SC: the three TFBs ----
    wire [31:0] s1, c1, s2, c2, s3, c3;
    wire        rng;
    kin_sincos3 sc (
        .clk(clk), .in_valid(in_valid), .t1(t1), .t2(t2), .t3(t3), .s1(s1), .c1(c1),
        .s2(s2), .c2(c2), .s3(s3), .c3(c3), .range_err(rng)
    );

    // ---- SC .. SC+MUL: the products of a constant ----
    wire [31:0] l2s3, l1c2, l2c3, l1s2, l1c1;
    f32_mul m_l2s3 (.clk(clk), .a(L2), .b(s3), .r(l2s3));
    f32_mul m_l1c2 (.clk(clk), .a(L1), .b(c2), .r(l1c2));
    f32_mul m_l2c3 (.clk(clk), .a(L2), .b(c3), .r(l2c3));
    f32_mul m_l1s2 (.clk(clk), .a(L1), .b(s2), .r(l1s2));
    f32_mul m_l1c1 (.clk(clk), .a(L1), .b(c1), .r(l1c1));
    wire [31:0] s3_m, c2_m;
    tfb_delay #(.W(64), .N(MUL)) d_s3c2 (.clk(clk), .d({s3, c2}), .q({s3_m, c2_m}));

    // ---- SC+MUL ..: x's sum, y's first sum, z's second products ----
    wire [31:0] xa, yu, zv1, zv2;
    f32_add        a_x (.clk(clk), .a(l2s3), .b(l1c2), .r(xa));
    f32_add        a_y (.clk(clk), .a(f32_neg(l2c3)), .b(l1s2), .r(yu));
`ifdef KIN_MUTANT_FK
    // mutant: L2*(c1*s3) instead of (L2*c1)*s3
    wire [31:0] c1s3;
    f32_mul m_c1s3 (.clk(clk), .a(c1), .b(s3), .r(c1s3));
    f32_mul m_zv1  (.clk(clk), .a(L2), .b(c1s3), .r(zv1));
`else
    wire [31:0] l2c1;
    f32_mul m_l2c1 (.clk(clk), .a(L2), .b(c1), .r(l2c1));
    f32_mul m_zv1  (.clk(clk), .a(l2c1), .b(s3_m), .r(zv1));
`endif
    f32_mul m_zv2  (.clk(clk), .a(l1c1), .b(c2_m), .r(zv2));

    // ---- SC+MUL+ADD ..: x's product, y's constant; SC+2MUL ..: z's sum ----
    wire [31:0] s1_ma, xm, yo, zw, zo;
    tfb_delay #(.W(32), .N(MUL + ADD)) d_s1 (.clk(clk), .d(s1), .q(s1_ma));
    f32_mul        m_x (.clk(clk), .a(s1_ma), .b(xa), .r(xm));
    f32_add        a_y3 (.clk(clk), .a(yu), .b(L3), .r(yo));
    f32_add        a_zw (.clk(clk), .a(zv1), .b(zv2), .r(zw));
    f32_add #(.SUB(1)) a_z (.clk(clk), .a(zw), .b(L4), .r(zo));

    // ---- line up ----
    wire [31:0] xm_d, yo_d;
    tfb_delay #(.W(32), .N(ADD + PIPE_M)) d_x (.clk(clk), .d(xm), .q(xm_d));
    tfb_delay #(.W(32), .N(MUL + PIPE_M)) d_y (.clk(clk), .d(yo), .q(yo_d));
    tfb_delay #(.W(32), .N(PIPE_M)) d_z (.clk(clk), .d(zo), .q(z));
    assign x = f32_neg(xm_d);
    assign y = yo_d;
    tfb_delay #(.W(1), .N(LATENCY - SC)) d_err (.clk(clk), .d(rng), .q(err));
    tfb_delay #(.W(192), .N(LATENCY - SC)) d_dbg (
        .clk(clk), .d({s1, c1, s2, c2, s3, c3}), .q(dbg));
    tfb_delay #(.W(1), .N(LATENCY)) d_valid (.clk(clk), .d(in_valid), .q(out_valid));
endmodule
