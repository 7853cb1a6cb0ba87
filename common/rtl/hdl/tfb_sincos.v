// TFB, rotation mode: sin and cos of an f32 angle, bit for bit the hybrid model's
// `Cordic::sin_cos` (tactile-math, cordic/datapath.rs) for |angle| < 3 pi.
//
// One sample a clock, LATENCY = ITER + 5 clocks with every stage a register (pipeline
// "sample"; the output register is the unit's, `UNIT_REG, the others `STAGE_REG: see
// pipe.vh and TFB_SINCOS_LAT in f32_lat.vh):
//   1    F2FP, part 1: unpack the f32, A = floor(angle 2^(FRAC+GUARD)), pick the
//        turn k (|angle| > pi: k = +-1); range_err for |angle| >= 3 pi, inf, NaN
//   2    F2FP, part 2: code = floor((A - k 2pi 2^(FRAC+GUARD) + h) / 2^GUARD)
//   3    quadrant fold into [-pi/2, pi/2] (subtract or add Q(pi), remember to negate)
//   4..  ITER CORDIC iterations, one per clock; x, y in [sWORD.(FRAC+1)], z in
//        [sWORD.FRAC], every shift rounded as the model rounds it
//   +1   sign and saturation to [-1, 1]
//   +1   FP2F: the nearest f32 (ties to even)
// Out-of-range inputs give NaN on both outputs with range_err set.
// Every constant is a parameter that `tactile hdl params` writes from the model
// (tfb_params.vh); the defaults below are placeholders, never a format.
module tfb_sincos #(
    parameter integer WORD = 16,
    parameter integer FRAC = 13,
    parameter integer ITER = 14,
    parameter integer NEAREST = 1,
    parameter integer GUARD = 32,
    parameter integer DEBUG = 0,
    parameter [31:0] GAIN = 0,
    parameter [31:0] PI_Q = 0,
    parameter [31:0] HALF_PI_Q = 0,
    parameter [32*32-1:0] ATAN = 0,
    parameter [127:0] TWO_PI = 0,
    parameter [31:0] PI_UP = 0,
    parameter [31:0] THREE_PI_UP = 0
) (
    input  wire            clk,
    input  wire            in_valid,
    input  wire [31:0]     angle,
    output wire            out_valid,
    output reg  [31:0]     sin_out,
    output reg  [31:0]     cos_out,
    output wire            range_err,
    // Stage-boundary taps, lined up with the outputs (DEBUG = 1; else 0).
    output wire [WORD-1:0] dbg_code,
    output wire [WORD-1:0] dbg_folded,
    output wire            dbg_flip,
    output wire [WORD-1:0] dbg_sin,
    output wire [WORD-1:0] dbg_cos
);
    localparam integer FP2F_W = WORD;
    `include "tfb_fp.vh"
    `include "f32_lat.vh"

    localparam integer LATENCY = `TFB_SINCOS_LAT(ITER);
    // |A| < 3 pi 2^(FRAC+GUARD) < 2^(FRAC+GUARD+4), a sign, one bit of headroom.
    localparam integer RW = FRAC + GUARD + 6;
    localparam [RW-1:0] TWO_PI_R = TWO_PI[RW-1:0];
    localparam [RW-1:0] HALF_R = (NEAREST != 0) ? ({{(RW-1){1'b0}}, 1'b1} << (GUARD - 1)) : {RW{1'b0}};
    localparam signed [WORD-1:0] ONE = {{(WORD-1){1'b0}}, 1'b1} << (FRAC + 1);
    localparam signed [WORD-1:0] PI_W = PI_Q[WORD-1:0];
    localparam signed [WORD-1:0] HALF_PI_W = HALF_PI_Q[WORD-1:0];

    // ---- 1: unpack, exact fixed point, turn ----
    wire        sgn = angle[31];
    wire [7:0]  ex = angle[30:23];
    wire [23:0] mag = {ex != 8'd0, angle[22:0]};
    reg  [RW-1:0] t;
    reg           st;
    integer       sh, nsh;
    always @* begin
        // angle = +-mag 2^(max(ex, 1) - 150)
        sh = (ex == 8'd0 ? 1 : ex) - 150 + FRAC + GUARD;
        nsh = -sh;                              // right shift, 1..24 where used
        if (ex > 8'd130) begin                  // |angle| >= 16: a range error anyway
            t = {RW{1'b0}};
            st = 1'b0;
        end else if (sh >= 0) begin             // sh <= FRAC + GUARD - 20 < 64
            t = {{(RW-24){1'b0}}, mag} << sh[5:0];
            st = 1'b0;
        end else if (sh > -25) begin
            t = {{(RW-24){1'b0}}, mag >> nsh[4:0]};
            st = |(mag & ~(24'hFFFFFF << nsh[4:0]));
        end else begin
            t = {RW{1'b0}};
            st = |mag;
        end
    end
    reg signed [RW-1:0] a1;
    reg                 kpos1, kneg1, err1;
    `STAGE_REG begin
        a1 <= sgn ? -$signed(t + st) : $signed(t);   // floor, also below the lsb
        kpos1 <= !sgn && angle[30:0] >= PI_UP[30:0];
        kneg1 <= sgn && angle[30:0] >= PI_UP[30:0];
        err1 <= angle[30:0] >= THREE_PI_UP[30:0];    // also inf and NaN
    end

    // ---- 2: reduce and round to the angle code ----
    wire signed [RW-1:0] w = a1 - (kpos1 ? $signed(TWO_PI_R) : 0)
                              + (kneg1 ? $signed(TWO_PI_R) : 0) + $signed(HALF_R);
    reg signed [WORD-1:0] code2;
    `STAGE_REG code2 <= w[GUARD +: WORD];

    // ---- 3: quadrant fold ----
    wire up = code2 > HALF_PI_W;
    wire down = code2 < -HALF_PI_W;
    reg signed [WORD-1:0] z3;
    reg                   flip3;
    `STAGE_REG begin
        z3 <= code2 - (up ? PI_W : 0) + (down ? PI_W : 0);
        flip3 <= up | down;
    end

    // ---- 4..: the iterations ----
    wire [WORD-1:0] xw [0:ITER];
    wire [WORD-1:0] yw [0:ITER];
    wire [WORD-1:0] zw [0:ITER];
    assign xw[0] = GAIN[WORD-1:0];
    assign yw[0] = {WORD{1'b0}};
    assign zw[0] = z3;
    genvar i;
    generate
        for (i = 0; i < ITER; i = i + 1) begin : it
            tfb_stage #(
                .WORD(WORD), .I(i), .NEAREST(NEAREST), .VECTORING(0), .ATAN_I(ATAN[i*32 +: 32])
            ) stage (
                .clk(clk), .x(xw[i]), .y(yw[i]), .z(zw[i]),
                .xn(xw[i+1]), .yn(yw[i+1]), .zn(zw[i+1])
            );
        end
    endgenerate
    wire flip_n;
    tfb_delay #(.W(1), .N(ITER * PIPE_S)) d_flip (.clk(clk), .d(flip3), .q(flip_n));

    // ---- sign and saturation ----
    wire signed [WORD-1:0] xf = xw[ITER];
    wire signed [WORD-1:0] yf = yw[ITER];
    wire signed [WORD:0] s_neg = flip_n ? -yf : yf;   // one more bit: -(-2^(W-1))
    wire signed [WORD:0] c_neg = flip_n ? -xf : xf;
    reg  signed [WORD-1:0] s_c, c_c;
    `STAGE_REG begin
        s_c <= s_neg > ONE ? ONE : (s_neg < -ONE ? -ONE : s_neg[WORD-1:0]);
        c_c <= c_neg > ONE ? ONE : (c_neg < -ONE ? -ONE : c_neg[WORD-1:0]);
    end

    // ---- FP2F ----
    wire err_n;
    tfb_delay #(.W(1), .N((ITER + 3) * PIPE_S)) d_err (.clk(clk), .d(err1), .q(err_n));
    reg err_o;
    `UNIT_REG begin
        sin_out <= err_n ? 32'h7FC0_0000 : fp2f(s_c, FRAC + 1);
        cos_out <= err_n ? 32'h7FC0_0000 : fp2f(c_c, FRAC + 1);
        err_o <= err_n;
    end
    assign range_err = err_o;
    tfb_delay #(.W(1), .N(LATENCY)) d_valid (.clk(clk), .d(in_valid), .q(out_valid));

    generate
        if (DEBUG != 0) begin : taps
            tfb_delay #(.W(WORD), .N((ITER + 2) * PIPE_S + PIPE_U)) d_code (.clk(clk), .d(code2), .q(dbg_code));
            tfb_delay #(.W(WORD + 1), .N((ITER + 1) * PIPE_S + PIPE_U)) d_fold (.clk(clk), .d({flip3, z3}), .q({dbg_flip, dbg_folded}));
            tfb_delay #(.W(2 * WORD), .N(PIPE_U)) d_sc (.clk(clk), .d({s_c, c_c}), .q({dbg_sin, dbg_cos}));
        end else begin : no_taps
            assign dbg_code = {WORD{1'b0}};
            assign dbg_folded = {WORD{1'b0}};
            assign dbg_flip = 1'b0;
            assign dbg_sin = {WORD{1'b0}};
            assign dbg_cos = {WORD{1'b0}};
        end
    endgenerate
endmodule
