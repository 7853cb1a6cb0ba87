// f32_add: fully pipelined IEEE-754 binary32 adder, bit-exact with Rust's f32 `+`
// (SUB = 1: `-`, computed as a + (-b)) on x86-64 SSE: round to nearest even,
// subnormal inputs and outputs (no flush to zero), overflow to +-inf,
// x + (-x) = +0, (-0) + (-0) = -0. A NaN input, or inf - inf, gives the
// canonical quiet NaN 32'h7FC00000 (IEEE leaves the payload open).
// One new a, b per clock; r appears LATENCY clocks later (LATENCY register stages
// from ports a, b to port r). No reset: pure datapath.
//
// Stage map (LATENCY = F32_ADD_LAT in f32_lat.vh: 4 when every stage is a register,
// pipeline "sample"; the last stage is the unit's output register, `UNIT_REG, the
// others `STAGE_REG, each a register or a wire as pipe.vh says):
//   1  unpack; order the operands by magnitude, x = larger, y = smaller;
//      exponent difference; specials (NaN, inf)
//   2  align y to x (right shift keeping guard, round and sticky bits), add or
//      subtract the significands
//   3  normalize: leading-zero count and left shift, limited so the exponent
//      stops at the subnormal one (a carry out is a shift of 0 with exponent + 1)
//   4  round to nearest even, pack, overflow to inf
//
// Why three extra bits are enough: when y is shifted by d >= 2 the difference
// loses at most one leading bit, so guard + round + sticky still decide the
// rounding exactly; when d <= 1 nothing is shifted out and the sum is exact.
module f32_add #(
    parameter integer SUB = 0        // 1: r = a - b
) (
    input  wire        clk,
    input  wire [31:0] a,            // f32 bits
    input  wire [31:0] b,            // f32 bits
    output reg  [31:0] r             // f32 bits of a + b (a - b)
);
localparam [31:0] QNAN = 32'h7FC00000;

`include "pipe.vh"
`include "f32_round.vh"

// Leading-zero count of a 28-bit word (28 when zero).
function [4:0] lzc28;
    input [27:0] x;
    integer i;
    begin
        lzc28 = 5'd28;
        for (i = 0; i < 28; i = i + 1)
            if (x[i]) lzc28 = 5'd27 - i[4:0];
    end
endfunction

// ---------------------------------------------------------------- stage 1
// Bit patterns of non-NaN values order like sign-magnitude integers, so the
// magnitude comparison is an integer compare of bits 30:0. A subnormal has
// exponent field 0 but the scale of field 1, and no leading one.
wire [31:0] bb    = (SUB != 0) ? {~b[31], b[30:0]} : b;
wire        a_nan = (a[30:23] == 8'hFF) && (a[22:0] != 23'd0);
wire        b_nan = (b[30:23] == 8'hFF) && (b[22:0] != 23'd0);
wire        a_inf = (a[30:0] == 31'h7F800000);
wire        b_inf = (b[30:0] == 31'h7F800000);
wire        swap  = (bb[30:0] > a[30:0]);
wire [31:0] x     = swap ? bb : a;                  // |x| >= |y|
wire [31:0] y     = swap ? a : bb;
// Exponent difference: both ways from the unswapped operands, then selected.
// (Written as xe - ye of the swapped operands, ABC shared its XORs with the
// comparator's carry chain, which made `swap` feed itself: a logically false
// but structural combinational loop, on which the netlist simulation hangs.)
wire [7:0]  ae    = (a[30:23] == 8'd0) ? 8'd1 : a[30:23];
wire [7:0]  be    = (bb[30:23] == 8'd0) ? 8'd1 : bb[30:23];
wire [7:0]  dab   = ae - be;
wire [7:0]  dba   = be - ae;
wire [7:0]  xe    = swap ? be : ae;
wire [7:0]  d     = swap ? dba : dab;               // xe - ye, 0..253
reg         sg1, sub1, nan1, inf1;
reg  [7:0]  e1;
reg  [4:0]  d1;
reg  [23:0] mx1, my1;
`STAGE_REG begin
    sg1  <= x[31];                                  // sign of the larger: of the result
    sub1 <= a[31] ^ bb[31];                         // effective subtraction
    nan1 <= a_nan | b_nan | (a_inf & b_inf & (a[31] ^ bb[31]));
    inf1 <= (x[30:0] == 31'h7F800000);              // inf +- finite, or inf + inf
    e1   <= xe;
    d1   <= (d > 8'd31) ? 5'd31 : d[4:0];           // >= 27 only feeds the sticky bit
    mx1  <= {x[30:23] != 8'd0, x[22:0]};
    my1  <= {y[30:23] != 8'd0, y[22:0]};
end

// ---------------------------------------------------------------- stage 2
// Significands with 3 bits below the LSB: guard, round, sticky. y is shifted
// in a 56-bit field (nothing falls off for d <= 31); the bits below the round
// bit OR into the sticky. Result S = {carry, 24 bits, G, R, S} >= 0.
wire [55:0] ysh = {my1, 32'd0} >> d1;
wire [26:0] yal = {ysh[55:30], |ysh[29:0]};
wire [26:0] xal = {mx1, 3'b000};
wire [27:0] sum = sub1 ? {1'b0, xal} - {1'b0, yal} : {1'b0, xal} + {1'b0, yal};
reg  [27:0] s2;
reg  [7:0]  e2;
reg         sg2, nan2, inf2;
`STAGE_REG begin
    s2   <= sum;
    e2   <= e1;
    // An exact zero is +0 from a subtraction (x + (-x)); from an addition both
    // operands were zeros of the same sign, which it keeps.
    sg2  <= (sum == 28'd0) ? (sg1 & ~sub1) : sg1;
    nan2 <= nan1;
    inf2 <= inf1;
end

// ---------------------------------------------------------------- stage 3
// Value = S * 2^(e - 127 - 26). Shift the leading one to bit 27 and set the
// exponent to e + 1 - shift, but shift at most e so the exponent stays >= 1:
// a result left without its leading one is subnormal (exponent field 0).
wire [4:0] lz  = lzc28(s2);
wire [7:0] sh  = ({3'd0, lz} > e2) ? e2 : {3'd0, lz};
reg  [27:0] n3;
reg  [8:0]  e3;
reg         sg3, nan3, inf3;
`STAGE_REG begin
    n3   <= s2 << sh[4:0];                          // sh <= 28
    e3   <= {1'b0, e2} + 9'd1 - {1'b0, sh};         // 1..255
    sg3  <= sg2;
    nan3 <= nan2;
    inf3 <= inf2;
end

// ---------------------------------------------------------------- stage 4
wire [30:0] mag = rnd_pack({1'b0, e3}, n3[27:4], n3[3], |n3[2:0]);
`UNIT_REG
    r <= nan3 ? QNAN : inf3 ? {sg3, 31'h7F800000} : {sg3, mag};

endmodule
