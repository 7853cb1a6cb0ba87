// IK-HSD: inverse kinematics, tool xyz to joint angles (elbow up), bit for bit the
// model's `ik` (tactile-math, kernels.rs, ik_taps) in the hybrid arithmetic: f32
// products, sums, quotients and square roots in Rust's order, each rounded once, two
// TFB atan2 (tfb_atan2) and two TFB acos (tfb_acos):
//
//   invalid = x, y or z not finite              -> angles +0.0, status 2
//   yl = y - L3;  zl = z + L4
//   far = max_of(max_of(|x|, |yl|), |zl|)       (max_of(a, b) = b > a ? b : a)
//   far > REACH4: x, yl, zl *= REACH2 / far     (clamped)
//   theta1 = -atan2(x, zl)
//   rr2 = x*x + zl*zl;  R = sqrt(rr2);  r2 = rr2 + yl*yl;  r = sqrt(r2)
//   cos_gamma = r > 0 ? (C_GAMMA + r2) / (TWO_L1 * r) : +0.0  (r = 0: clamped iff L1 != L2)
//   gamma = acos(clamp_unit(cos_gamma));  beta = atan2(yl, R)
//   alpha = acos(clamp_unit((C_ALPHA - r2) / D_ALPHA))
//   theta2 = gamma + beta;  theta3 = (theta2 + alpha) - HALF_PI
//   clamp_unit(a): a > 1 -> 1 (clamped if a > ONE_TOL); a < -1 -> -1 (clamped if
//   a < -ONE_TOL); NaN -> 1, clamped; else a.
//   status: 0 reachable, 1 clamped, 2 invalid.
//
// One sample a clock, no back-pressure, no reset on the datapath. Stage map (ADD, MUL,
// DIV, SQRT the f32 units' latencies; AT of tfb_atan2, AC of tfb_acos: ITER + 4 and
// ITER + 37 in the pipeline "sample", f32_lat.vh's formulas in any), times from the
// input (each "+ 1" below is a stage register, PIPE_S: 0 outside "sample"):
//
//   T_A  = ADD            yl = y - L3, zl = z + L4 (2 f32_add); x delayed ADD
//   T_A+1                 max_of(|x|, |yl|) (comparator, register)
//   T_F  = T_A + 2        far = max_of(.., |zl|) (comparator, register);
//                         far > REACH4 (comparator) delayed to T_M
//   T_K  = T_F + DIV      k = REACH2 / far (f32_div)
//   T_M  = T_K + MUL      x*k, yl*k, zl*k (3 f32_mul); x, yl, zl delayed to T_M
//   T_S  = T_M + 1        xs, ys, zs: the scaled or the plain values (mux, register)
//   T_S  .. +AT           atan = atan2(xs, zs)                       (tfb_atan2)
//   T_S  .. +MUL          xs*xs, zs*zs, ys*ys                        (3 f32_mul)
//   T_RR = T_S+MUL+ADD    rr2 = xs*xs + zs*zs                        (f32_add)
//   T_R2 = T_RR + ADD     r2 = rr2 + ys*ys (ys*ys delayed ADD)       (f32_add)
//   T_BR = T_RR + SQRT    R = sqrt(rr2)                              (f32_sqrt)
//   T_R  = T_R2 + SQRT    r = sqrt(r2)                               (f32_sqrt)
//   T_R2 .. +ADD          C_GAMMA + r2, C_ALPHA - r2                 (2 f32_add)
//   T_R  .. +MUL          TWO_L1 * r                                 (f32_mul)
//   T_CG = T_R+MUL+DIV    (C_GAMMA + r2) / (TWO_L1 r)   (f32_div; numerator delayed
//                         SQRT + MUL - ADD); (C_ALPHA - r2) / D_ALPHA (f32_div), its
//                         quotient delayed to T_CG; r > 0 delayed to T_CG
//   T_C  = T_CG + 1       cg, ca: r = 0 select and clamp_unit, flags (register)
//   T_C  .. +AC           gamma = acos(cg), alpha = acos(ca)         (2 tfb_acos)
//   T_BR .. +AT           beta = atan2(ys, R) (ys delayed T_BR - T_S) (tfb_atan2)
//   T_G  = T_C + AC       gamma + beta (beta delayed T_G - T_BR - AT) (f32_add)
//   T_G+ADD               theta2 + alpha (alpha delayed ADD)         (f32_add)
//   T_G+2ADD .. +ADD      theta3 = .. - HALF_PI                      (f32_add)
//   theta1 = -atan delayed to the end, theta2 delayed 2 ADD; the invalid flag and
//   the clamp flags delayed to the end, where they select the outputs.
//
// In the paper's architecture (pipe.vh's PIPE_M = 1: no register inside any unit) every
// output passes one register more, so that a sample takes one clock, of a period as
// long as the whole datapath.
//
//   LATENCY = 6 ADD + 3 MUL + 2 DIV + SQRT + AC + 4 PIPE_S + PIPE_M
//           (in "sample": (ITER + 41) + 6 F32_ADD_LAT + 3 F32_MUL_LAT + 2 F32_DIV_LAT
//           + F32_SQRT_LAT)
//
// dbg = {xs, ys, zs, atan, rr2, big_r, r2, r, cg, gamma, beta, ca, alpha} (xs in the
// top 32 bits), each lined up with the outputs: xs, ys, zs after the optional scaling,
// atan before its negation, cg and ca the clamped acos arguments. Meaningless when the
// status is 2.
// KIN_MUTANT_IK: r2 summed as xs*xs + (zs*zs + ys*ys), same latency.
module kin_ik (
    input  wire             clk,
    input  wire             in_valid,
    input  wire [31:0]      x, y, z,
    output wire             out_valid,
    output wire [31:0]      t1, t2, t3,
    output wire [1:0]       status,
    output wire [32*13-1:0] dbg
);
    `include "tfb_params.vh"
    `include "kin_params.vh"
    `include "f32_lat.vh"
    `include "f32_fn.vh"

    localparam integer ADD = F32_ADD_LAT;
    localparam integer MUL = F32_MUL_LAT;
    localparam integer DIV = F32_DIV_LAT;
    localparam integer SQRT = F32_SQRT_LAT;
    localparam integer AT = `TFB_VECTOR_LAT(ITER);     // tfb_atan2's LATENCY
    localparam integer AC = `TFB_ACOS_LAT(ITER);       // tfb_acos's LATENCY
    localparam integer T_A = ADD;
    localparam integer T_F = T_A + 2 * PIPE_S;
    localparam integer T_K = T_F + DIV;
    localparam integer T_M = T_K + MUL;
    localparam integer T_S = T_M + PIPE_S;
    localparam integer T_RR = T_S + MUL + ADD;
    localparam integer T_R2 = T_RR + ADD;
    localparam integer T_BR = T_RR + SQRT;
    localparam integer T_R = T_R2 + SQRT;
    localparam integer T_CG = T_R + MUL + DIV;
    localparam integer T_CA = T_R2 + ADD + DIV;
    localparam integer T_C = T_CG + PIPE_S;
    localparam integer T_G = T_C + AC;
    localparam integer T_B = T_BR + AT;
    localparam integer T_END = T_G + 3 * ADD;
    localparam integer LATENCY = T_END + PIPE_M;
    localparam [31:0] ZERO = 32'h0000_0000;
    localparam [31:0] ONE = 32'h3F80_0000;
    localparam [31:0] M_ONE = 32'hBF80_0000;

    // The only difference of latencies that could be negative: the numerator of
    // cos gamma waits for the root (SQRT + MUL >= ADD).
    generate
        if (SQRT + MUL < ADD) begin : bad_latencies
            kin_ik_needs_sqrt_plus_mul_ge_add error_ ();
        end
    endgenerate

    // ---- 0: invalid input ----
    wire inv0 = !(f32_is_finite(x) && f32_is_finite(y) && f32_is_finite(z));

    // ---- 0 .. T_A: the shoulder offsets ----
    wire [31:0] xa, yl, zl;
    f32_add #(.SUB(1)) a_yl (.clk(clk), .a(y), .b(L3), .r(yl));
    f32_add            a_zl (.clk(clk), .a(z), .b(L4), .r(zl));
    tfb_delay #(.W(32), .N(ADD)) d_xa (.clk(clk), .d(x), .q(xa));

    // ---- T_A .. T_F: far = max_of(max_of(|x|, |yl|), |zl|) ----
    reg [31:0] m1, zl_abs1, far;
    `STAGE_REG begin
        m1 <= f32_gt(f32_abs(yl), f32_abs(xa)) ? f32_abs(yl) : f32_abs(xa);
        zl_abs1 <= f32_abs(zl);
        far <= f32_gt(zl_abs1, m1) ? zl_abs1 : m1;
    end
    wire big_m;
    tfb_delay #(.W(1), .N(DIV + MUL)) d_big (.clk(clk), .d(f32_gt(far, REACH4)), .q(big_m));

    // ---- T_F .. T_M: pull a far target in ----
    wire [31:0] k, xk, yk, zk, xa_m, yl_m, zl_m;
    f32_div q_k (.clk(clk), .a(REACH2), .b(far), .r(k));
    tfb_delay #(.W(96), .N(T_K - T_A)) d_xyz_k (.clk(clk), .d({xa, yl, zl}), .q({xa_m, yl_m, zl_m}));
    f32_mul m_xk (.clk(clk), .a(xa_m), .b(k), .r(xk));
    f32_mul m_yk (.clk(clk), .a(yl_m), .b(k), .r(yk));
    f32_mul m_zk (.clk(clk), .a(zl_m), .b(k), .r(zk));
    wire [31:0] xa_s, yl_s, zl_s;
    tfb_delay #(.W(96), .N(MUL)) d_xyz_s (.clk(clk), .d({xa_m, yl_m, zl_m}), .q({xa_s, yl_s, zl_s}));
    reg [31:0] xs, ys, zs;
    reg        big_s;
    `STAGE_REG begin
        xs <= big_m ? xk : xa_s;
        ys <= big_m ? yk : yl_s;
        zs <= big_m ? zk : zl_s;
        big_s <= big_m;
    end

    // ---- T_S ..: theta1's atan2 ----
    wire [31:0] atan;
    tfb_atan2 #(
        .WORD(WORD), .FRAC(FRAC), .ITER(ITER), .NEAREST(NEAREST),
        .PI_Q(PI_Q), .PI_FLOOR(PI_FLOOR), .ATAN(ATAN)
    ) tfb_th1 (
        .clk(clk), .in_valid(1'b1), .y(xs), .x(zs), .out_valid(), .angle(atan),
        .dbg_x(), .dbg_y(), .dbg_z()
    );

    // ---- T_S .. T_R: the squares, their sums and roots ----
    wire [31:0] xx, yy, zz, yy_d, rr2, r2, big_r, r;
    f32_mul m_xx (.clk(clk), .a(xs), .b(xs), .r(xx));
    f32_mul m_zz (.clk(clk), .a(zs), .b(zs), .r(zz));
    f32_mul m_yy (.clk(clk), .a(ys), .b(ys), .r(yy));
    f32_add a_rr2 (.clk(clk), .a(xx), .b(zz), .r(rr2));
`ifdef KIN_MUTANT_IK
    // mutant: r2 = xs*xs + (zs*zs + ys*ys)
    wire [31:0] zy, xx_d;
    f32_add a_zy (.clk(clk), .a(zz), .b(yy), .r(zy));
    tfb_delay #(.W(32), .N(ADD)) d_xx (.clk(clk), .d(xx), .q(xx_d));
    f32_add a_r2 (.clk(clk), .a(xx_d), .b(zy), .r(r2));
`else
    tfb_delay #(.W(32), .N(ADD)) d_yy (.clk(clk), .d(yy), .q(yy_d));
    f32_add a_r2 (.clk(clk), .a(rr2), .b(yy_d), .r(r2));
`endif
    f32_sqrt q_bigr (.clk(clk), .a(rr2), .r(big_r));
    f32_sqrt q_r (.clk(clk), .a(r2), .r(r));

    // ---- T_BR ..: beta = atan2(ys, R) ----
    wire [31:0] ys_br, beta;
    tfb_delay #(.W(32), .N(T_BR - T_S)) d_ys (.clk(clk), .d(ys), .q(ys_br));
    tfb_atan2 #(
        .WORD(WORD), .FRAC(FRAC), .ITER(ITER), .NEAREST(NEAREST),
        .PI_Q(PI_Q), .PI_FLOOR(PI_FLOOR), .ATAN(ATAN)
    ) tfb_beta (
        .clk(clk), .in_valid(1'b1), .y(ys_br), .x(big_r), .out_valid(), .angle(beta),
        .dbg_x(), .dbg_y(), .dbg_z()
    );

    // ---- T_R2 .. T_CG: the two acos arguments ----
    wire [31:0] num_g, num_a, num_g_d, den_g, cg_q, ca_q, ca_q_d;
    f32_add            a_ng (.clk(clk), .a(C_GAMMA), .b(r2), .r(num_g));
    f32_add #(.SUB(1)) a_na (.clk(clk), .a(C_ALPHA), .b(r2), .r(num_a));
    f32_mul            m_dg (.clk(clk), .a(TWO_L1), .b(r), .r(den_g));
    tfb_delay #(.W(32), .N(T_R + MUL - T_R2 - ADD)) d_ng (.clk(clk), .d(num_g), .q(num_g_d));
    f32_div            q_cg (.clk(clk), .a(num_g_d), .b(den_g), .r(cg_q));
    f32_div            q_ca (.clk(clk), .a(num_a), .b(D_ALPHA), .r(ca_q));
    tfb_delay #(.W(32), .N(T_CG - T_CA)) d_ca (.clk(clk), .d(ca_q), .q(ca_q_d));
    wire rpos;
    tfb_delay #(.W(1), .N(MUL + DIV)) d_rpos (.clk(clk), .d(f32_gt(r, ZERO)), .q(rpos));

    // ---- T_CG .. T_C: r = 0, clamp_unit ----
    // clamp_unit(a) and its flag, as kernels.rs: > 1, < -1, finite, NaN.
    function [32:0] clamp_unit;                  // {clamped, value}
        input [31:0] a;
        begin
            if (f32_gt(a, ONE))
                clamp_unit = {f32_gt(a, ONE_TOL), ONE};
            else if (f32_lt(a, M_ONE))
                clamp_unit = {f32_lt(a, f32_neg(ONE_TOL)), M_ONE};
            else if (f32_is_finite(a))
                clamp_unit = {1'b0, a};
            else
                clamp_unit = {1'b1, ONE};
        end
    endfunction
    wire [32:0] cg_u = clamp_unit(rpos ? cg_q : ZERO);
    wire [32:0] ca_u = clamp_unit(ca_q_d);
    reg  [31:0] cg, ca;
    reg         flag_c;
    `STAGE_REG begin
        cg <= cg_u[31:0];
        ca <= ca_u[31:0];
        flag_c <= cg_u[32] | ca_u[32] | (!rpos && L1_NE_L2 != 0);
    end

    // ---- T_C .. T_G: gamma and alpha ----
    wire [31:0] gamma, alpha;
    tfb_acos #(
        .WORD(WORD), .FRAC(FRAC), .ITER(ITER), .NEAREST(NEAREST),
        .PI_Q(PI_Q), .PI_FLOOR(PI_FLOOR), .ATAN(ATAN)
    ) tfb_gamma (
        .clk(clk), .in_valid(1'b1), .a(cg), .out_valid(), .angle(gamma),
        .dbg_root(), .dbg_x(), .dbg_y(), .dbg_z()
    );
    tfb_acos #(
        .WORD(WORD), .FRAC(FRAC), .ITER(ITER), .NEAREST(NEAREST),
        .PI_Q(PI_Q), .PI_FLOOR(PI_FLOOR), .ATAN(ATAN)
    ) tfb_alpha (
        .clk(clk), .in_valid(1'b1), .a(ca), .out_valid(), .angle(alpha),
        .dbg_root(), .dbg_x(), .dbg_y(), .dbg_z()
    );

    // ---- T_G .. LATENCY: theta2, theta3 ----
    wire [31:0] beta_g, alpha_d, th2, th3a, th3_c, th3;
    tfb_delay #(.W(32), .N(T_G - T_B)) d_beta (.clk(clk), .d(beta), .q(beta_g));
    f32_add            a_th2 (.clk(clk), .a(gamma), .b(beta_g), .r(th2));
    tfb_delay #(.W(32), .N(ADD)) d_alpha (.clk(clk), .d(alpha), .q(alpha_d));
    f32_add            a_th3a (.clk(clk), .a(th2), .b(alpha_d), .r(th3a));
    f32_add #(.SUB(1)) a_th3 (.clk(clk), .a(th3a), .b(HALF_PI), .r(th3_c));
    tfb_delay #(.W(32), .N(PIPE_M)) d_th3 (.clk(clk), .d(th3_c), .q(th3));

    // ---- the outputs: invalid and clamp flags select ----
    wire [31:0] atan_o, th2_o;
    wire inv_o, big_o, flag_o;
    tfb_delay #(.W(32), .N(LATENCY - T_S - AT)) d_th1 (.clk(clk), .d(atan), .q(atan_o));
    tfb_delay #(.W(32), .N(2 * ADD + PIPE_M)) d_th2 (.clk(clk), .d(th2), .q(th2_o));
    tfb_delay #(.W(1), .N(LATENCY)) d_inv (.clk(clk), .d(inv0), .q(inv_o));
    tfb_delay #(.W(1), .N(LATENCY - T_S)) d_bigo (.clk(clk), .d(big_s), .q(big_o));
    tfb_delay #(.W(1), .N(LATENCY - T_C)) d_flag (.clk(clk), .d(flag_c), .q(flag_o));
    assign t1 = inv_o ? ZERO : f32_neg(atan_o);
    assign t2 = inv_o ? ZERO : th2_o;
    assign t3 = inv_o ? ZERO : th3;
    assign status = inv_o ? 2'd2 : {1'b0, big_o | flag_o};
    tfb_delay #(.W(1), .N(LATENCY)) d_valid (.clk(clk), .d(in_valid), .q(out_valid));

    // ---- the taps, lined up with the outputs ----
    tfb_delay #(.W(96), .N(LATENCY - T_S)) d_t_s (.clk(clk), .d({xs, ys, zs}), .q(dbg[32*13-1 : 32*10]));
    assign dbg[32*10-1 : 32*9] = atan_o;
    tfb_delay #(.W(32), .N(LATENCY - T_RR)) d_t_rr2 (.clk(clk), .d(rr2), .q(dbg[32*9-1 : 32*8]));
    tfb_delay #(.W(32), .N(LATENCY - T_BR)) d_t_br (.clk(clk), .d(big_r), .q(dbg[32*8-1 : 32*7]));
    tfb_delay #(.W(32), .N(LATENCY - T_R2)) d_t_r2 (.clk(clk), .d(r2), .q(dbg[32*7-1 : 32*6]));
    tfb_delay #(.W(32), .N(LATENCY - T_R)) d_t_r (.clk(clk), .d(r), .q(dbg[32*6-1 : 32*5]));
    tfb_delay #(.W(32), .N(LATENCY - T_C)) d_t_cg (.clk(clk), .d(cg), .q(dbg[32*5-1 : 32*4]));
    tfb_delay #(.W(32), .N(LATENCY - T_G)) d_t_g (.clk(clk), .d(gamma), .q(dbg[32*4-1 : 32*3]));
    tfb_delay #(.W(32), .N(LATENCY - T_G)) d_t_b (.clk(clk), .d(beta_g), .q(dbg[32*3-1 : 32*2]));
    tfb_delay #(.W(32), .N(LATENCY - T_C)) d_t_ca (.clk(clk), .d(ca), .q(dbg[32*2-1 : 32*1]));
    tfb_delay #(.W(32), .N(LATENCY - T_G)) d_t_a (.clk(clk), .d(alpha), .q(dbg[32*1-1 : 0]));
endmodule
