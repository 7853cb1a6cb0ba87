// Synthesis tops: one TFB function each, in the format of tfb_params.vh (written by
// `tactile hdl rtl`), with the stage taps off. `tactile hdl synth` synthesizes these.
module top_sincos (
    input wire clk, input wire in_valid, input wire [31:0] angle,
    output wire out_valid, output wire [31:0] sin_out, output wire [31:0] cos_out,
    output wire range_err
);
    `include "tfb_params.vh"
    tfb_sincos #(
        .WORD(WORD), .FRAC(FRAC), .ITER(ITER), .NEAREST(NEAREST), .GUARD(GUARD),
        .GAIN(GAIN), .PI_Q(PI_Q), .HALF_PI_Q(HALF_PI_Q), .ATAN(ATAN), .TWO_PI(TWO_PI),
        .PI_UP(PI_UP), .THREE_PI_UP(THREE_PI_UP)
    ) u (
        .clk(clk), .in_valid(in_valid), .angle(angle), .out_valid(out_valid),
        .sin_out(sin_out), .cos_out(cos_out), .range_err(range_err),
        .dbg_code(), .dbg_folded(), .dbg_flip(), .dbg_sin(), .dbg_cos()
    );
endmodule

module top_atan2 (
    input wire clk, input wire in_valid, input wire [31:0] y, input wire [31:0] x,
    output wire out_valid, output wire [31:0] angle
);
    `include "tfb_params.vh"
    tfb_atan2 #(
        .WORD(WORD), .FRAC(FRAC), .ITER(ITER), .NEAREST(NEAREST),
        .PI_Q(PI_Q), .PI_FLOOR(PI_FLOOR), .ATAN(ATAN)
    ) u (
        .clk(clk), .in_valid(in_valid), .y(y), .x(x), .out_valid(out_valid),
        .angle(angle), .dbg_x(), .dbg_y(), .dbg_z()
    );
endmodule

module top_acos (
    input wire clk, input wire in_valid, input wire [31:0] a,
    output wire out_valid, output wire [31:0] angle
);
    `include "tfb_params.vh"
    tfb_acos #(
        .WORD(WORD), .FRAC(FRAC), .ITER(ITER), .NEAREST(NEAREST),
        .PI_Q(PI_Q), .PI_FLOOR(PI_FLOOR), .ATAN(ATAN)
    ) u (
        .clk(clk), .in_valid(in_valid), .a(a), .out_valid(out_valid), .angle(angle),
        .dbg_root(), .dbg_x(), .dbg_y(), .dbg_z()
    );
endmodule
