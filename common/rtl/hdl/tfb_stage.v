// One CORDIC iteration i, one clock (a `STAGE_REG: a wire when pipe.vh says so): both
// modes, every register WORD bits.
// sigma = +1 turns (x, y) counter-clockwise by atan(2^-i) and takes the angle off z:
//   x' = x - sigma ((y + b) >>> i),  y' = y + sigma ((x + b) >>> i),  z' = z - sigma a_i
// with b = 2^(i-1) for round-half-up shifts (NEAREST, i >= 1), else 0. Rotation mode
// drives z to 0 (sigma = +1 while z >= 0); vectoring drives y to 0 (sigma = +1 while
// y < 0). The same shifter serves both modes, so the deliberately wrong variants
// (TFB_MUTANT_SHIFT, TFB_MUTANT_ROUND) change every function at once.
module tfb_stage #(
    parameter integer WORD = 16,
    parameter integer I = 0,
    parameter integer NEAREST = 1,
    parameter integer VECTORING = 0,
    parameter [31:0] ATAN_I = 0
) (
    input  wire                   clk,
    input  wire signed [WORD-1:0] x,
    input  wire signed [WORD-1:0] y,
    input  wire signed [WORD-1:0] z,
    output reg  signed [WORD-1:0] xn,
    output reg  signed [WORD-1:0] yn,
    output reg  signed [WORD-1:0] zn
);
`ifdef TFB_MUTANT_SHIFT
    localparam integer SH = (I == 3) ? 4 : I;  // a deliberately wrong shifter
`else
    localparam integer SH = I;
`endif
`ifdef TFB_MUTANT_ROUND
    localparam integer B = 0;                   // truncating where it must round
`else
    localparam integer B = (NEAREST != 0 && SH > 0) ? (1 << (SH - 1)) : 0;
`endif
`include "pipe.vh"
    wire signed [WORD-1:0] xs = (x + B) >>> SH;
    wire signed [WORD-1:0] ys = (y + B) >>> SH;
    wire signed [WORD-1:0] a = ATAN_I[WORD-1:0];
    wire ccw = VECTORING != 0 ? y[WORD-1] : !z[WORD-1];
    `STAGE_REG begin
        if (ccw) begin
            xn <= x - ys;
            yn <= y + xs;
            zn <= z - a;
        end else begin
            xn <= x + ys;
            yn <= y - xs;
            zn <= z + a;
        end
    end
endmodule
