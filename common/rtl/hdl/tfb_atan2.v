// TFB atan2(y, x): bit for bit the hybrid model's `Cordic::atan2`, every f32 input
// (infinities become +-1 and the other input a signed zero, as the model's
// `sanitize` does; NaN in gives NaN out). LATENCY = ITER + 4 clocks (tfb_vector)
// with every stage a register (TFB_VECTOR_LAT in f32_lat.vh).
module tfb_atan2 #(
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
    input  wire [31:0]     y,
    input  wire [31:0]     x,
    output wire            out_valid,
    output wire [31:0]     angle,
    output wire [WORD-1:0] dbg_x,
    output wire [WORD-1:0] dbg_y,
    output wire [WORD-1:0] dbg_z
);
    `include "f32_lat.vh"
    localparam integer LATENCY = `TFB_VECTOR_LAT(ITER);
    wire x_inf = x[30:0] == 31'h7F80_0000;
    wire y_inf = y[30:0] == 31'h7F80_0000;
    wire nan = x[30:23] == 8'hFF && !x_inf || y[30:23] == 8'hFF && !y_inf;
    wire inf = x_inf | y_inf;
    // An infinite input becomes +-1, the other a signed zero.
    wire [31:0] xs = x_inf ? {x[31], 31'h3F80_0000} : (inf ? {x[31], 31'd0} : x);
    wire [31:0] ys = y_inf ? {y[31], 31'h3F80_0000} : (inf ? {y[31], 31'd0} : y);
    tfb_vector #(
        .WORD(WORD), .FRAC(FRAC), .ITER(ITER), .NEAREST(NEAREST), .ACOS(0), .DEBUG(DEBUG),
        .PI_Q(PI_Q), .PI_FLOOR(PI_FLOOR), .ATAN(ATAN)
    ) core (
        .clk(clk), .in_valid(in_valid), .y(ys), .x(xs), .nan(nan),
        .out_valid(out_valid), .angle(angle), .dbg_x(dbg_x), .dbg_y(dbg_y), .dbg_z(dbg_z)
    );
endmodule
