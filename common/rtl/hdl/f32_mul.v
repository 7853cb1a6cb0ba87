// f32_mul: fully pipelined IEEE-754 binary32 multiplier, bit-exact with Rust's
// f32 `*` on x86-64 SSE: round to nearest even, subnormal inputs and outputs
// (products that underflow round into the subnormals or to zero, correctly, with
// no double rounding), overflow to +-inf, sign = sign(a) ^ sign(b) also for zeros
// and infinities. A NaN input, or 0 * inf, gives the canonical quiet NaN
// 32'h7FC00000.
// One new a, b per clock; r appears LATENCY clocks later (LATENCY register stages
// from ports a, b to port r). No reset: pure datapath.
//
// Stage map (LATENCY = F32_MUL_LAT in f32_lat.vh: 4 when every stage is a register,
// pipeline "sample"; the last stage is the unit's output register, `UNIT_REG, the
// others `STAGE_REG, each a register or a wire as pipe.vh says):
//   1  unpack; normalize subnormal significands (leading one to bit 23, the
//      exponent goes below 1); exponent sum; specials (NaN, inf, zero)
//   2  24x24 significand product (plain `*` on registered operands: DSP48E1s)
//   3  product pipeline register (the DSP's MREG/PREG)
//   4  normalize the product (1 bit), denormalize a subnormal result (right
//      shift with sticky), round to nearest even, pack, overflow to inf
module f32_mul (
    input  wire        clk,
    input  wire [31:0] a,            // f32 bits
    input  wire [31:0] b,            // f32 bits
    output reg  [31:0] r             // f32 bits of a * b
);
localparam [31:0] QNAN = 32'h7FC00000;

`include "pipe.vh"
`include "f32_round.vh"

// ---------------------------------------------------------------- stage 1
// |x| = m * 2^(e - 127 - 23) with m in [2^23, 2^24): a subnormal (field 0, scale
// of field 1) is shifted up by its leading zeros and its e drops to 1 - lz
// (down to -22). Exponents are 10-bit two's complement from here on.
wire [23:0] ma  = {a[30:23] != 8'd0, a[22:0]};
wire [23:0] mb  = {b[30:23] != 8'd0, b[22:0]};
wire [4:0]  lza = lzc24(ma);
wire [4:0]  lzb = lzc24(mb);
wire [9:0]  ea  = {2'b00, (a[30:23] == 8'd0) ? 8'd1 : a[30:23]} - {5'd0, lza};
wire [9:0]  eb  = {2'b00, (b[30:23] == 8'd0) ? 8'd1 : b[30:23]} - {5'd0, lzb};
wire        a_nan  = (a[30:23] == 8'hFF) && (a[22:0] != 23'd0);
wire        b_nan  = (b[30:23] == 8'hFF) && (b[22:0] != 23'd0);
wire        a_inf  = (a[30:0] == 31'h7F800000);
wire        b_inf  = (b[30:0] == 31'h7F800000);
wire        a_zero = (a[30:0] == 31'd0);
wire        b_zero = (b[30:0] == 31'd0);
reg  [23:0] ma1, mb1;
reg  [9:0]  e1;
reg         sg1, nan1, inf1, zero1;
`STAGE_REG begin
    ma1   <= ma << lza;                             // zero stays zero (flagged)
    mb1   <= mb << lzb;
    e1    <= ea + eb - 10'd127;                     // -171..381
    sg1   <= a[31] ^ b[31];
    nan1  <= a_nan | b_nan | (a_inf & b_zero) | (a_zero & b_inf);
    inf1  <= a_inf | b_inf;                         // when not NaN
    zero1 <= a_zero | b_zero;                       // when not NaN
end

// ---------------------------------------------------------------- stages 2-3
// P = ma * mb in [2^46, 2^48); |a*b| = P * 2^(e - 127 - 46).
reg  [47:0] p2, p3;
reg  [9:0]  e2, e3;
reg         sg2, nan2, inf2, zero2, sg3, nan3, inf3, zero3;
`STAGE_REG begin
    p2 <= ma1 * mb1;
    p3 <= p2;
    {e2, sg2, nan2, inf2, zero2} <= {e1, sg1, nan1, inf1, zero1};
    {e3, sg3, nan3, inf3, zero3} <= {e2, sg2, nan2, inf2, zero2};
end

// ---------------------------------------------------------------- stage 4
// Leading one to bit 47: the result is n4[47:24] (24 bits), guard n4[23],
// sticky n4[22:0], with biased exponent e4. If e4 < 1 the result is subnormal:
// shift right by 1 - e4 (the shifted-out bits join the sticky) and pack with
// e = 1. A shift of 25 or more leaves only sticky: rounds to 0; 31 is plenty.
wire [47:0] n4   = p3[47] ? p3 : {p3[46:0], 1'b0};
wire [9:0]  e4   = e3 + {9'd0, p3[47]};
wire        sub4 = e4[9] | (e4 == 10'd0);           // e4 <= 0
wire [9:0]  ds   = 10'd1 - e4;                      // shift for a subnormal
wire [4:0]  sh4  = !sub4 ? 5'd0 : (ds > 10'd31) ? 5'd31 : ds[4:0];
wire [47:0] d4   = n4 >> sh4;
wire        lost = |(n4 & ~({48{1'b1}} << sh4));    // bits shifted out
wire [9:0]  ep4  = sub4 ? 10'd1 : (e4 > 10'd255) ? 10'd255 : e4;   // 255: overflow
wire [30:0] mag  = rnd_pack(ep4, d4[47:24], d4[23], (|d4[22:0]) | lost);
`UNIT_REG
    r <= nan3  ? QNAN :
         inf3  ? {sg3, 31'h7F800000} :
         zero3 ? {sg3, 31'd0} :
                 {sg3, mag};

endmodule
