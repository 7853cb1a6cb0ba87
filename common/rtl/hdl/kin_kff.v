// KFF-HMD: kinesthetic feedback force tau = J(theta)^T F, bit for bit the model's `kff`
// (tactile-math, kernels.rs: kff_from_trig, jacobian_from_trig) in the hybrid
// arithmetic: three TFBs (tfb_sincos), the Jacobian (the paper's JM) and the products
// with the force (its KF), every f32 operation in Rust's order, each rounded once:
//
//   j11 = -(c1 * (L2*s3 + L1*c2))          j21 = +0.0 (a constant, still multiplied)
//   j31 = -((L1*c2)*s1) - (L2*s3)*s1
//   j12 = (L1*s1)*s2     j22 = L1*c2       j32 = -((L1*s2)*c1)
//   j13 = -((L2*s1)*c3)  j23 = L2*s3       j33 = (L2*c3)*c1
//   tau_i = (J[0][i]*f1 + J[1][i]*f2) + J[2][i]*f3
//
// j22 and j23 are the same f32 products as j11's L1*c2 and L2*s3: computed once.
// One sample a clock, no back-pressure, no reset on the datapath. Stage map (SC the
// latency of tfb_sincos, ITER + 5 in the pipeline "sample"; MUL, ADD the f32 units'
// latencies):
//
//   0 .. SC                 sin, cos of t1, t2, t3                  (3 tfb_sincos)
//   SC .. +MUL              L2*s3 (j23), L1*c2 (j22), L1*s1, L1*s2, L2*s1, L2*c3 (6 mul)
//   SC+MUL .. +ADD          a = L2*s3 + L1*c2                               (f32_add)
//   SC+MUL .. +MUL          (L1*c2)*s1, (L2*s3)*s1, j12, j32, j13, j33  (6 f32_mul)
//                           s1, s2, c1, c3 delayed MUL
//   SC+MUL+ADD .. +MUL      j11 = -(c1 * a)            c1 delayed MUL+ADD  (f32_mul)
//   SC+2MUL .. +ADD         j31 = -((L1*c2)*s1) - (L2*s3)*s1                (f32_add)
//   JT = SC+2MUL+ADD        the nine J entries meet (j12.. delayed ADD, j22, j23
//                           delayed MUL+ADD); f1..f3 delayed JT
//   JT .. +MUL              J[k][i] * f_k, nine products (j21*f2 too)   (9 f32_mul)
//   JT+MUL .. +ADD          J[0][i]*f1 + J[1][i]*f2                     (3 f32_add)
//   JT+MUL+ADD .. +ADD      ... + J[2][i]*f3       J[2][i]*f3 delayed ADD (3 f32_add)
//
//   LATENCY = (ITER + 5) + 3 F32_MUL_LAT + 3 F32_ADD_LAT (+ PIPE_M)
//
// In the paper's architecture (pipe.vh's PIPE_M = 1: no register inside any unit) every
// output passes one register more, so that a sample takes one clock, of a period as
// long as the whole datapath.
//
// err: OR of the three TFBs' range_err, lined up with the outputs. dbg = {s1, c1, s2,
// c2, s3, c3, j11, j12, j13, j21, j22, j23, j31, j32, j33} (s1 in the top 32 bits),
// each lined up with the outputs.
// KIN_MUTANT_KFF: every tau summed as J[0][i]*f1 + (J[1][i]*f2 + J[2][i]*f3), same
// latency.
module kin_kff (
    input  wire          clk,
    input  wire          in_valid,
    input  wire [31:0]   t1, t2, t3,
    input  wire [31:0]   f1, f2, f3,
    output wire          out_valid,
    output wire [31:0]   tau1, tau2, tau3,
    output wire          err,
    output wire [32*15-1:0] dbg
);
    `include "tfb_params.vh"
    `include "kin_params.vh"
    `include "f32_lat.vh"
    `include "f32_fn.vh"

    localparam integer SC = `TFB_SINCOS_LAT(ITER);     // tfb_sincos's LATENCY
    localparam integer MUL = F32_MUL_LAT;
    localparam integer ADD = F32_ADD_LAT;
    localparam integer JT = SC + 2 * MUL + ADD;        // the Jacobian is ready
    localparam integer LATENCY = SC + 3 * MUL + 3 * ADD + PIPE_M;
    localparam [31:0] ZERO = 32'h0000_0000;

    // ---- 0 .. SC: the three TFBs ----
    wire [31:0] s1, c1, s2, c2, s3, c3;
    wire        rng;
    kin_sincos3 sc (
        .clk(clk), .in_valid(in_valid), .t1(t1), .t2(t2), .t3(t3), .s1(s1), .c1(c1),
        .s2(s2), .c2(c2), .s3(s3), .c3(c3), .range_err(rng)
    );

    // ---- SC .. SC+MUL: the products of a constant ----
    wire [31:0] l2s3, l1c2, l1s1, l1s2, l2s1, l2c3;
    f32_mul m_l2s3 (.clk(clk), .a(L2), .b(s3), .r(l2s3));     // also j23
    f32_mul m_l1c2 (.clk(clk), .a(L1), .b(c2), .r(l1c2));     // also j22
    f32_mul m_l1s1 (.clk(clk), .a(L1), .b(s1), .r(l1s1));
    f32_mul m_l1s2 (.clk(clk), .a(L1), .b(s2), .r(l1s2));
    f32_mul m_l2s1 (.clk(clk), .a(L2), .b(s1), .r(l2s1));
    f32_mul m_l2c3 (.clk(clk), .a(L2), .b(c3), .r(l2c3));
    wire [31:0] s1_m, s2_m, c1_m, c3_m;
    tfb_delay #(.W(128), .N(MUL)) d_trig (
        .clk(clk), .d({s1, s2, c1, c3}), .q({s1_m, s2_m, c1_m, c3_m}));

    // ---- SC+MUL ..: the second products, j11's sum ----
    wire [31:0] j11_a, n1, n2, j12, j32_p, j13_p, j33;
    f32_add m_j11a (.clk(clk), .a(l2s3), .b(l1c2), .r(j11_a));
    f32_mul m_n1  (.clk(clk), .a(l1c2), .b(s1_m), .r(n1));     // (L1*c2)*s1
    f32_mul m_n2  (.clk(clk), .a(l2s3), .b(s1_m), .r(n2));     // (L2*s3)*s1
    f32_mul m_j12 (.clk(clk), .a(l1s1), .b(s2_m), .r(j12));
    f32_mul m_j32 (.clk(clk), .a(l1s2), .b(c1_m), .r(j32_p));
    f32_mul m_j13 (.clk(clk), .a(l2s1), .b(c3_m), .r(j13_p));
    f32_mul m_j33 (.clk(clk), .a(l2c3), .b(c1_m), .r(j33));

    // ---- SC+MUL+ADD ..: j11's product; SC+2MUL ..: j31's difference ----
    wire [31:0] c1_ma, j11_p, j31;
    tfb_delay #(.W(32), .N(ADD)) d_c1 (.clk(clk), .d(c1_m), .q(c1_ma));
    f32_mul m_j11 (.clk(clk), .a(c1_ma), .b(j11_a), .r(j11_p));
    f32_add #(.SUB(1)) a_j31 (.clk(clk), .a(f32_neg(n1)), .b(n2), .r(j31));

    // ---- JT: the Jacobian lined up ----
    wire [31:0] j11 = f32_neg(j11_p);
    wire [31:0] j12_d, j32_d, j13_d, j33_d, j22_d, j23_d;
    tfb_delay #(.W(128), .N(ADD)) d_j2 (
        .clk(clk), .d({j12, f32_neg(j32_p), f32_neg(j13_p), j33}),
        .q({j12_d, j32_d, j13_d, j33_d}));
    tfb_delay #(.W(64), .N(MUL + ADD)) d_j1 (
        .clk(clk), .d({l1c2, l2s3}), .q({j22_d, j23_d}));
    wire [31:0] j21 = ZERO;
    wire [31:0] f1_d, f2_d, f3_d;
    tfb_delay #(.W(96), .N(JT)) d_f (.clk(clk), .d({f1, f2, f3}), .q({f1_d, f2_d, f3_d}));

    // ---- JT .. JT+MUL: the nine products with the force ----
    wire [31:0] p11, p21, p31, p12, p22, p32, p13, p23, p33;   // pki = J[k][i] * f_k
    f32_mul m_p11 (.clk(clk), .a(j11),   .b(f1_d), .r(p11));
    f32_mul m_p21 (.clk(clk), .a(j21),   .b(f2_d), .r(p21));   // 0 * f2: -0, NaN matter
    f32_mul m_p31 (.clk(clk), .a(j31),   .b(f3_d), .r(p31));
    f32_mul m_p12 (.clk(clk), .a(j12_d), .b(f1_d), .r(p12));
    f32_mul m_p22 (.clk(clk), .a(j22_d), .b(f2_d), .r(p22));
    f32_mul m_p32 (.clk(clk), .a(j32_d), .b(f3_d), .r(p32));
    f32_mul m_p13 (.clk(clk), .a(j13_d), .b(f1_d), .r(p13));
    f32_mul m_p23 (.clk(clk), .a(j23_d), .b(f2_d), .r(p23));
    f32_mul m_p33 (.clk(clk), .a(j33_d), .b(f3_d), .r(p33));

    // ---- JT+MUL ..: the two sums of each tau ----
    wire [31:0] q1, q2, q3, w1, w2, w3, tau1_c, tau2_c, tau3_c;
`ifdef KIN_MUTANT_KFF
    // mutant: J[0][i]*f1 + (J[1][i]*f2 + J[2][i]*f3)
    f32_add a_q1 (.clk(clk), .a(p21), .b(p31), .r(q1));
    f32_add a_q2 (.clk(clk), .a(p22), .b(p32), .r(q2));
    f32_add a_q3 (.clk(clk), .a(p23), .b(p33), .r(q3));
    tfb_delay #(.W(96), .N(ADD)) d_w (.clk(clk), .d({p11, p12, p13}), .q({w1, w2, w3}));
    f32_add a_t1 (.clk(clk), .a(w1), .b(q1), .r(tau1_c));
    f32_add a_t2 (.clk(clk), .a(w2), .b(q2), .r(tau2_c));
    f32_add a_t3 (.clk(clk), .a(w3), .b(q3), .r(tau3_c));
`else
    f32_add a_q1 (.clk(clk), .a(p11), .b(p21), .r(q1));
    f32_add a_q2 (.clk(clk), .a(p12), .b(p22), .r(q2));
    f32_add a_q3 (.clk(clk), .a(p13), .b(p23), .r(q3));
    tfb_delay #(.W(96), .N(ADD)) d_w (.clk(clk), .d({p31, p32, p33}), .q({w1, w2, w3}));
    f32_add a_t1 (.clk(clk), .a(q1), .b(w1), .r(tau1_c));
    f32_add a_t2 (.clk(clk), .a(q2), .b(w2), .r(tau2_c));
    f32_add a_t3 (.clk(clk), .a(q3), .b(w3), .r(tau3_c));
`endif
    tfb_delay #(.W(96), .N(PIPE_M)) d_tau (
        .clk(clk), .d({tau1_c, tau2_c, tau3_c}), .q({tau1, tau2, tau3}));

    // ---- line up the flags and taps ----
    tfb_delay #(.W(1), .N(LATENCY - SC)) d_err (.clk(clk), .d(rng), .q(err));
    tfb_delay #(.W(192), .N(LATENCY - SC)) d_dbg_t (
        .clk(clk), .d({s1, c1, s2, c2, s3, c3}), .q(dbg[32*15-1 : 32*9]));
    tfb_delay #(.W(288), .N(LATENCY - JT)) d_dbg_j (
        .clk(clk), .d({j11, j12_d, j13_d, j21, j22_d, j23_d, j31, j32_d, j33_d}),
        .q(dbg[32*9-1 : 0]));
    tfb_delay #(.W(1), .N(LATENCY)) d_valid (.clk(clk), .d(in_valid), .q(out_valid));
endmodule
