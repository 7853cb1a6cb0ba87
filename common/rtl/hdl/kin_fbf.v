// FBF-HSD: the feedback force F = h * (obj - env) per axis, bit for bit the model's
// `fbf` (tactile-math, kernels.rs): one f32 subtraction, then one f32 product, each
// rounded once (round to nearest even), the three axes side by side.
//
// One sample a clock, no back-pressure, no reset on the datapath.
//
//   clock 0                 o, e, h in
//   0 .. ADD                d_i = o_i - e_i           (3 f32_add, SUB)   h delayed ADD
//   ADD .. ADD+MUL          F_i = h_i * d_i           (3 f32_mul)        d delayed MUL (dbg)
//
//   LATENCY = F32_ADD_LAT + F32_MUL_LAT (+ PIPE_M)
//
// In the paper's architecture (pipe.vh's PIPE_M = 1: no register inside any unit) every
// output passes one register more, so that a sample takes one clock, of a period as
// long as the whole datapath.
//
// dbg = {d1, d2, d3}, lined up with f1..f3.
// KIN_MUTANT_FBF: the distributed form F = h*o - h*e (a plausible rewrite that rounds
// twice before the subtraction): same latency, different bits.
module kin_fbf (
    input  wire        clk,
    input  wire        in_valid,
    input  wire [31:0] o1, o2, o3,
    input  wire [31:0] e1, e2, e3,
    input  wire [31:0] h1, h2, h3,
    output wire        out_valid,
    output wire [31:0] f1, f2, f3,
    output wire [95:0] dbg
);
    `include "tfb_params.vh"
    `include "kin_params.vh"
    `include "f32_lat.vh"
    `include "f32_fn.vh"

    localparam integer LATENCY = F32_ADD_LAT + F32_MUL_LAT + PIPE_M;

    wire [95:0] o = {o1, o2, o3};
    wire [95:0] e = {e1, e2, e3};
    wire [95:0] h = {h1, h2, h3};
    wire [95:0] d, d_out, h_d, f;

    genvar i;
    generate
        for (i = 0; i < 3; i = i + 1) begin : axis
            // d = obj - env
            f32_add #(.SUB(1)) sub_d (.clk(clk), .a(o[32*i +: 32]), .b(e[32*i +: 32]), .r(d[32*i +: 32]));
`ifdef KIN_MUTANT_FBF
            // mutant: h*o - h*e
            wire [31:0] ho, he;
            f32_mul mul_ho (.clk(clk), .a(h[32*i +: 32]), .b(o[32*i +: 32]), .r(ho));
            f32_mul mul_he (.clk(clk), .a(h[32*i +: 32]), .b(e[32*i +: 32]), .r(he));
            f32_add #(.SUB(1)) sub_f (.clk(clk), .a(ho), .b(he), .r(f[32*i +: 32]));
`else
            // F = h * d
            f32_mul mul_f (.clk(clk), .a(h_d[32*i +: 32]), .b(d[32*i +: 32]), .r(f[32*i +: 32]));
`endif
        end
    endgenerate
    tfb_delay #(.W(96), .N(F32_ADD_LAT)) d_h (.clk(clk), .d(h), .q(h_d));
    tfb_delay #(.W(96), .N(F32_MUL_LAT + PIPE_M)) d_d (.clk(clk), .d(d), .q(d_out));
    tfb_delay #(.W(96), .N(PIPE_M)) d_f (.clk(clk), .d(f), .q({f1, f2, f3}));
    tfb_delay #(.W(1), .N(LATENCY)) d_valid (.clk(clk), .d(in_valid), .q(out_valid));

    assign dbg = d_out;
endmodule
