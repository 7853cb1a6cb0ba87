// TFB, vectoring mode: the angle of (x, y), bit for bit the hybrid model's vectoring
// (`Cordic::atan2`, and with ACOS = 1 the back end of `Cordic::acos`).
//
// One sample a clock, LATENCY = ITER + 4 clocks with every stage a register (pipeline
// "sample"; the output register is the unit's, `UNIT_REG, the others `STAGE_REG: see
// pipe.vh and TFB_VECTOR_LAT in f32_lat.vh):
//   1    F2FP: both inputs scaled by one power of two so that max(|x|, |y|) is in
//        [0.5, 1) (an exponent subtraction), then floor(v 2^FRAC + h) each
//   2    half-plane fold: x < 0 negates both, z starts at +-pi by y's sign bit
//   3..  ITER iterations, one per clock, x, y, z in [sWORD.FRAC]; the decision is y's sign
//   +1   add the offset, saturate to +-floor(pi 2^FRAC), (0, 0) gives 0, ACOS clamps at 0
//   +1   FP2F: the nearest f32 (ties to even); NaN in gives NaN out
// The inputs must be finite (tfb_atan2 turns infinities into what the model makes of
// them); `nan` marks a sample whose output is NaN.
module tfb_vector #(
    parameter integer WORD = 16,
    parameter integer FRAC = 13,
    parameter integer ITER = 14,
    parameter integer NEAREST = 1,
    parameter integer ACOS = 0,
    parameter integer DEBUG = 0,
    parameter [31:0] PI_Q = 0,
    parameter [31:0] PI_FLOOR = 0,
    parameter [32*32-1:0] ATAN = 0
) (
    input  wire            clk,
    input  wire            in_valid,
    input  wire [31:0]     y,
    input  wire [31:0]     x,
    input  wire            nan,
    output wire            out_valid,
    output reg  [31:0]     angle,
    output wire [WORD-1:0] dbg_x,
    output wire [WORD-1:0] dbg_y,
    output wire [WORD-1:0] dbg_z
);
    localparam integer FP2F_W = WORD;
    `include "tfb_fp.vh"
    `include "f32_lat.vh"

    localparam integer LATENCY = `TFB_VECTOR_LAT(ITER);
    // Both positive and below 2^(WORD-1): one zero bit on top makes them signed.
    localparam signed [WORD:0] PI_W = {1'b0, PI_Q[WORD-1:0]};
    localparam signed [WORD:0] PI_FLOOR_W = {1'b0, PI_FLOOR[WORD-1:0]};

    // floor(+-sig 2^sh + h) in half units, sh <= 6: the F2FP of one component.
    function signed [WORD-1:0] f2fp;
        input        neg;
        input [23:0] sig;
        input integer sh;                 // value = sig 2^(sh - 1) in angle lsb
        reg   [39:0] t;
        reg          st;
        reg   signed [41:0] h2;
        integer      nsh;
        begin
            nsh = -sh;                         // right shift, 1..24 where used
            if (sh >= 0) begin                 // sh <= FRAC - 23 <= 6
                t = {16'd0, sig} << sh[2:0];
                st = 1'b0;
            end else if (sh > -25) begin
                t = {16'd0, sig >> nsh[4:0]};
                st = |(sig & ~(24'hFFFFFF << nsh[4:0]));
            end else begin
                t = 40'd0;
                st = |sig;
            end
            h2 = neg ? (NEAREST != 0 ? 42'sd1 : 42'sd0) - $signed({2'b0, t}) - st
                     : $signed({2'b0, t}) + (NEAREST != 0 ? 42'sd1 : 42'sd0);
            f2fp = h2 >>> 1;
        end
    endfunction

    // ---- 1: F2FP ----
    integer ex, ey, emax;
    reg signed [WORD-1:0] xc1, yc1;
    reg ysgn1, nan1;
    always @* begin
        ex = f32_exp(x);
        ey = f32_exp(y);
        emax = ex > ey ? ex : ey;
        if (emax < -149) emax = -149;
    end
    `STAGE_REG begin
        xc1 <= f2fp(x[31], f32_sig(x), ex - emax + FRAC - 23);
        yc1 <= f2fp(y[31], f32_sig(y), ey - emax + FRAC - 23);
        ysgn1 <= y[31];
        nan1 <= nan;
    end

    // ---- 2: half plane ----
    reg signed [WORD-1:0] x2, y2;
    reg signed [WORD:0]   z0_2;
    reg zero2;
    `STAGE_REG begin
        x2 <= xc1[WORD-1] ? -xc1 : xc1;
        y2 <= xc1[WORD-1] ? -yc1 : yc1;
        z0_2 <= xc1[WORD-1] ? (ysgn1 ? -PI_W : PI_W) : 0;
        zero2 <= (xc1 | yc1) == 0;
    end

    // ---- 3..: the iterations ----
    wire [WORD-1:0] xw [0:ITER];
    wire [WORD-1:0] yw [0:ITER];
    wire [WORD-1:0] zw [0:ITER];
    assign xw[0] = x2;
    assign yw[0] = y2;
    assign zw[0] = {WORD{1'b0}};
    genvar i;
    generate
        for (i = 0; i < ITER; i = i + 1) begin : it
            tfb_stage #(
                .WORD(WORD), .I(i), .NEAREST(NEAREST), .VECTORING(1), .ATAN_I(ATAN[i*32 +: 32])
            ) stage (
                .clk(clk), .x(xw[i]), .y(yw[i]), .z(zw[i]),
                .xn(xw[i+1]), .yn(yw[i+1]), .zn(zw[i+1])
            );
        end
    endgenerate
    wire signed [WORD:0] z0_n;
    wire zero_n;
    tfb_delay #(.W(WORD + 2), .N(ITER * PIPE_S)) d_z0 (.clk(clk), .d({zero2, z0_2}), .q({zero_n, z0_n}));

    // ---- offset, saturation ----
    wire signed [WORD-1:0] zf = zw[ITER];
    wire signed [WORD+1:0] sum = zf + z0_n;
    reg  signed [WORD-1:0] zc;
    `STAGE_REG begin
        if (zero_n || (ACOS != 0 && sum < 0))
            zc <= {WORD{1'b0}};
        else if (sum > PI_FLOOR_W)
            zc <= PI_FLOOR_W[WORD-1:0];
        else if (sum < -PI_FLOOR_W)
            zc <= -PI_FLOOR_W[WORD-1:0];
        else
            zc <= sum[WORD-1:0];
    end

    // ---- FP2F ----
    wire nan_n;
    tfb_delay #(.W(1), .N((ITER + 2) * PIPE_S)) d_nan (.clk(clk), .d(nan1), .q(nan_n));
    `UNIT_REG
        angle <= nan_n ? 32'h7FC0_0000 : fp2f(zc, FRAC);
    tfb_delay #(.W(1), .N(LATENCY)) d_valid (.clk(clk), .d(in_valid), .q(out_valid));

    generate
        if (DEBUG != 0) begin : taps
            tfb_delay #(.W(2 * WORD), .N((ITER + 2) * PIPE_S + PIPE_U)) d_xy (.clk(clk), .d({xc1, yc1}), .q({dbg_x, dbg_y}));
            tfb_delay #(.W(WORD), .N(PIPE_U)) d_zc (.clk(clk), .d(zc), .q(dbg_z));
        end else begin : no_taps
            assign dbg_x = {WORD{1'b0}};
            assign dbg_y = {WORD{1'b0}};
            assign dbg_z = {WORD{1'b0}};
        end
    endgenerate
endmodule
