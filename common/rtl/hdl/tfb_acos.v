// TFB acos(a): bit for bit the hybrid model's `Cordic::acos`, every f32 input. The
// model computes acos(a) = atan2(sqrt((1 - a)(1 + a)), a) with a clamped to [-1, 1]
// and the root in f32; here the f32 front end (tfb_sqrt1m, 33 clocks) feeds the
// vectoring block (tfb_vector with its clamp at 0). LATENCY = 33 + ITER + 4 clocks with
// every stage a register (TFB_ACOS_LAT in f32_lat.vh).
module tfb_acos #(
    parameter integer WORD = 16,
    parameter integer FRAC = 13,
    parameter integer ITER = 14,
    parameter integer NEAREST = 1,
    parameter integer DEBUG = 0,
    parameter [31:0] PI_Q = 0,
    parameter [31:0] PI_FLOOR = 0,
    parameter [32*32-1:0] ATAN = 0
) (
    input  wire            clk,
    input  wire            in_valid,
    input  wire [31:0]     a,
    output wire            out_valid,
    output wire [31:0]     angle,
    output wire [31:0]     dbg_root,
    output wire [WORD-1:0] dbg_x,
    output wire [WORD-1:0] dbg_y,
    output wire [WORD-1:0] dbg_z
);
    `include "f32_lat.vh"
    localparam integer FRONT = `TFB_SQRT1M_LAT;
    localparam integer LATENCY = `TFB_ACOS_LAT(ITER);
    wire nan = a[30:23] == 8'hFF && a[22:0] != 23'd0;
    wire [31:0] root, clamped;
    wire nan_f, valid_f;
    // A NaN takes the front end's path as 0 and comes out NaN.
    tfb_sqrt1m front (.clk(clk), .a(nan ? 32'd0 : a), .s(root), .a_clamp(clamped));
    tfb_delay #(.W(2), .N(FRONT)) d_front (.clk(clk), .d({nan, in_valid}), .q({nan_f, valid_f}));
    tfb_vector #(
        .WORD(WORD), .FRAC(FRAC), .ITER(ITER), .NEAREST(NEAREST), .ACOS(1), .DEBUG(DEBUG),
        .PI_Q(PI_Q), .PI_FLOOR(PI_FLOOR), .ATAN(ATAN)
    ) core (
        .clk(clk), .in_valid(valid_f), .y(root), .x(clamped), .nan(nan_f),
        .out_valid(out_valid), .angle(angle), .dbg_x(dbg_x), .dbg_y(dbg_y), .dbg_z(dbg_z)
    );
    generate
        if (DEBUG != 0) begin : taps
            tfb_delay #(.W(32), .N(`TFB_VECTOR_LAT(ITER))) d_root (.clk(clk), .d(root), .q(dbg_root));
        end else begin : no_taps
            assign dbg_root = 32'd0;
        end
    endgenerate
endmodule
