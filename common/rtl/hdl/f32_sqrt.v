// f32_sqrt: fully pipelined IEEE-754 binary32 square root, bit-exact with Rust's
// f32::sqrt on x86-64 SSE (sqrtss): correctly rounded to nearest even,
// subnormal inputs (every result is normal: sqrt(2^-149) = 2^-74.5),
// sqrt(+-0) = +-0, sqrt(+inf) = +inf. A NaN input or a negative non-zero input
// (-inf included) gives the canonical quiet NaN 32'h7FC00000.
// One new a per clock; r appears LATENCY clocks later (LATENCY register stages
// from port a to port r). No reset: pure datapath.
//
// Stage map (LATENCY = F32_SQRT_LAT in f32_lat.vh: 28 when every stage is a register,
// pipeline "sample"; the last stage is the unit's output register, `UNIT_REG, the
// others `STAGE_REG, each a register or a wire as pipe.vh says):
//   1      unpack; normalize a subnormal significand (leading one to bit 23);
//          specials (NaN, inf, zero)
//   2      make the exponent even, form the 50-bit radicand, halve the exponent
//   3-27   25 restoring square-root stages, one root bit each (24 result bits
//          + guard); the final remainder != 0 is the sticky bit
//   28     round to nearest even, pack
// The digit stages are those of tfb_sqrt1m. A root never lies exactly halfway
// between two f32 (its square would need more than 24 bits), so guard + sticky
// round it correctly, and it never overflows or carries into a new exponent.
module f32_sqrt (
    input  wire        clk,
    input  wire [31:0] a,            // f32 bits
    output reg  [31:0] r             // f32 bits of sqrt(a)
);
localparam NQ      = 25;             // root bits: 24 significant + guard
localparam [31:0] QNAN = 32'h7FC00000;

// Round {m, g, st} (24-bit significand with its leading one, guard, sticky) to
// nearest even; a carry out of the significand bumps e (kept for safety: it
// cannot happen for a root). Returns {exponent, fraction}.
// F32_MUTANT_ROUND (test only): truncate instead, to show the co-simulation fails.
function [30:0] rnd_root;
    input [7:0]  e;
    input [23:0] m;
    input        g;
    input        st;
    reg   [24:0] q;
    begin
`ifdef F32_MUTANT_ROUND
        q = {1'b0, m};
`else
        q = {1'b0, m} + {24'd0, g & (st | m[0])};
`endif
        rnd_root = q[24] ? {e + 8'd1, 23'd0} : {e, q[22:0]};
    end
endfunction

`include "pipe.vh"
`include "f32_round.vh"

// ---------------------------------------------------------------- stage 1
// a = m * 2^(e - 127 - 23) with m in [2^23, 2^24): a subnormal (field 0, scale
// of field 1) is shifted up by its leading zeros and its e drops to 1 - lz
// (down to -22; 10-bit two's complement).
// Special results: 0 = finite positive root, 1 = +-0 (a itself), 2 = +inf, 3 = NaN.
wire [23:0] ma    = {a[30:23] != 8'd0, a[22:0]};
wire [4:0]  lza   = lzc24(ma);
wire        a_nan  = (a[30:23] == 8'hFF) && (a[22:0] != 23'd0);
wire        a_zero = (a[30:0] == 31'd0);
wire        a_inf  = (a[30:0] == 31'h7F800000);
wire [1:0]  spc   = (a_nan | (a[31] & ~a_zero)) ? 2'd3 :
                    a_inf                        ? 2'd2 :
                    a_zero                       ? 2'd1 : 2'd0;
reg  [23:0] m1;
reg  [9:0]  e1;
reg  [1:0]  spc1;
reg         sg1;
`STAGE_REG begin
    m1   <= ma << lza;
    e1   <= {2'b00, (a[30:23] == 8'd0) ? 8'd1 : a[30:23]} - {5'd0, lza};
    spc1 <= spc;
    sg1  <= a[31];                                  // sign of a zero input
end

// ---------------------------------------------------------------- stage 2
// sqrt(m * 2^(E-23)), E = e - 127. Make the exponent even: with E odd (e even)
// use 2m. Radicand R = m*2^25 (E even) or m*2^26 (E odd) so that Q = isqrt(R)
// has 1 integer + 24 fraction bits; result exponent floor(E/2), biased
// floor((e + 127) / 2) (e + 127 >= 105 > 0, so a plain shift).
wire [9:0] e127 = e1 + 10'd127;
reg  [49:0] rad2;
reg  [10:0] sd2;                                    // {special, sign, exponent}
`STAGE_REG begin
    rad2 <= e1[0] ? {1'b0, m1, 25'd0} : {m1, 26'd0};
    sd2  <= {spc1, sg1, e127[8:1]};
end

// ---------------------------------------------------------------- stages 3-27
// Flat buses between stages (slice k = output register of digit stage k).
reg [50*NQ-1:0] q_rad /*verilator split_var*/;                              // radicand, consumed 2 bits/stage
reg [26*NQ-1:0] q_rem /*verilator split_var*/;                              // partial remainder (< 2^26)
reg [25*NQ-1:0] q_root /*verilator split_var*/;                             // partial root
reg [11*NQ-1:0] q_side /*verilator split_var*/;                             // {special, sign, exponent}

genvar k;
generate
    for (k = 0; k < NQ; k = k + 1) begin : sq
        wire [49:0] rad_i;
        wire [25:0] rem_i;
        wire [24:0] root_i;
        wire [10:0] side_i;
        if (k == 0) begin : first
            assign rad_i  = rad2;
            assign rem_i  = 26'd0;
            assign root_i = 25'd0;
            assign side_i = sd2;
        end else begin : next
            assign rad_i  = q_rad [50*(k-1) +: 50];
            assign rem_i  = q_rem [26*(k-1) +: 26];
            assign root_i = q_root[25*(k-1) +: 25];
            assign side_i = q_side[11*(k-1) +: 11];
        end
        // Restoring step: bring down 2 radicand bits, try subtracting 4*root+1.
        wire [27:0] rsh   = {rem_i, rad_i[49:48]};
        wire [27:0] trial = {1'b0, root_i, 2'b01};
        wire        ge    = (rsh >= trial);
        wire [27:0] dif   = rsh - trial;
        `STAGE_REG begin
            q_rad [50*k +: 50] <= {rad_i[47:0], 2'b00};
            q_rem [26*k +: 26] <= ge ? dif[25:0] : rsh[25:0];
            q_root[25*k +: 25] <= {root_i[23:0], ge};
            q_side[11*k +: 11] <= side_i;
        end
    end
endgenerate

// ---------------------------------------------------------------- stage 28
// Q[24:1] = significand, Q[0] = guard, sticky = remainder != 0.
wire [24:0] qf   = q_root[25*(NQ-1) +: 25];
wire        qst  = |q_rem[26*(NQ-1) +: 26];
wire [10:0] qsd  = q_side[11*(NQ-1) +: 11];
wire [30:0] mag  = rnd_root(qsd[7:0], qf[24:1], qf[0], qst);
`UNIT_REG
    r <= (qsd[10:9] == 2'd3) ? QNAN :
         (qsd[10:9] == 2'd2) ? 32'h7F800000 :
         (qsd[10:9] == 2'd1) ? {qsd[8], 31'd0} :
                               {1'b0, mag};

endmodule
