// f32_div: fully pipelined IEEE-754 binary32 divider, bit-exact with Rust's f32
// `/` on x86-64 SSE: correctly rounded to nearest even, subnormal inputs and
// outputs (quotients that underflow round into the subnormals or to zero, with
// no double rounding), overflow to +-inf, sign = sign(a) ^ sign(b) also for
// zeros and infinities: x/0 = +-inf (x != 0), x/inf = +-0, inf/x = +-inf.
// A NaN input, 0/0 or inf/inf gives the canonical quiet NaN 32'h7FC00000.
// One new a, b per clock; r appears LATENCY clocks later (LATENCY register stages
// from ports a, b to port r). No reset: pure datapath.
//
// Stage map (LATENCY = F32_DIV_LAT in f32_lat.vh: 28 when every stage is a register,
// pipeline "sample"; the last stage is the unit's output register, `UNIT_REG, the
// others `STAGE_REG, each a register or a wire as pipe.vh says):
//   1      unpack; normalize subnormal significands (leading one to bit 23);
//          exponent difference; specials (NaN, inf, zero)
//   2      pre-scale: if ma < mb use 2 ma (exponent - 1) so the quotient is in [1, 2)
//   3-27   25 restoring division stages, one quotient bit each (24 result bits
//          + guard); the final remainder != 0 is the sticky bit
//   28     denormalize a subnormal result (right shift with sticky), round to
//          nearest even, pack, overflow to inf
module f32_div (
    input  wire        clk,
    input  wire [31:0] a,            // f32 bits, dividend
    input  wire [31:0] b,            // f32 bits, divisor
    output reg  [31:0] r             // f32 bits of a / b
);
localparam NQ      = 25;             // quotient bits: 24 significant + guard
localparam [31:0] QNAN = 32'h7FC00000;

`include "pipe.vh"
`include "f32_round.vh"

// ---------------------------------------------------------------- stage 1
// |x| = m * 2^(e - 127 - 23) with m in [2^23, 2^24): a subnormal (field 0, scale
// of field 1) is shifted up by its leading zeros and its e drops to 1 - lz
// (down to -22). Exponents are 10-bit two's complement from here on.
// Special results, a 2-bit code carried beside the digit stages:
// 0 = finite non-zero quotient, 1 = zero, 2 = inf, 3 = NaN.
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
wire [1:0]  spc    = (a_nan | b_nan | (a_zero & b_zero) | (a_inf & b_inf)) ? 2'd3 :
                     (a_inf | b_zero)                                      ? 2'd2 :
                     (a_zero | b_inf)                                      ? 2'd1 : 2'd0;
reg  [23:0] ma1, mb1;
reg  [9:0]  e1;
reg         sg1;
reg  [1:0]  spc1;
`STAGE_REG begin
    ma1  <= ma << lza;
    mb1  <= mb << lzb;
    e1   <= ea - eb + 10'd127;                      // -149..403
    sg1  <= a[31] ^ b[31];
    spc1 <= spc;
end

// ---------------------------------------------------------------- stage 2
// ma/mb is in (1/2, 2); with ma < mb divide 2 ma instead (exponent - 1), so the
// quotient Q = floor(ma' * 2^24 / mb) has its leading one at bit 24.
// A zero divisor (special) would make the digit stages meaningless: harmless.
wire        lt1 = (ma1 < mb1);
reg  [24:0] rem2;                                   // partial remainder, < 2 mb
reg  [23:0] dv2;                                    // divisor
reg  [12:0] sd2;                                    // {special, sign, exponent}
`STAGE_REG begin
    rem2 <= lt1 ? {ma1, 1'b0} : {1'b0, ma1};
    dv2  <= mb1;
    sd2  <= {spc1, sg1, e1 - {9'd0, lt1}};          // e: -150..403
end

// ---------------------------------------------------------------- stages 3-27
// Restoring division, one quotient bit a stage: with R < 2D, the bit is R >= D;
// then R := 2 (R - bit D) < 2D again.
// Flat buses between stages (slice k = output register of digit stage k).
reg [25*NQ-1:0] q_rem /*verilator split_var*/;                              // partial remainder (< 2^25)
reg [24*NQ-1:0] q_dv /*verilator split_var*/;                               // divisor
reg [25*NQ-1:0] q_quo /*verilator split_var*/;                              // quotient bits so far
reg [13*NQ-1:0] q_side /*verilator split_var*/;                             // {special, sign, exponent}

genvar k;
generate
    for (k = 0; k < NQ; k = k + 1) begin : dst
        wire [24:0] rem_i;
        wire [23:0] dv_i;
        wire [24:0] quo_i;
        wire [12:0] side_i;
        if (k == 0) begin : first
            assign rem_i  = rem2;
            assign dv_i   = dv2;
            assign quo_i  = 25'd0;
            assign side_i = sd2;
        end else begin : next
            assign rem_i  = q_rem [25*(k-1) +: 25];
            assign dv_i   = q_dv  [24*(k-1) +: 24];
            assign quo_i  = q_quo [25*(k-1) +: 25];
            assign side_i = q_side[13*(k-1) +: 13];
        end
        wire        ge  = (rem_i >= {1'b0, dv_i});
        wire [24:0] dif = rem_i - {1'b0, dv_i};      // < D when ge
        wire [24:0] nr  = ge ? dif : rem_i;          // < D < 2^24
        `STAGE_REG begin
            q_rem [25*k +: 25] <= {nr[23:0], 1'b0};
            q_dv  [24*k +: 24] <= dv_i;
            q_quo [25*k +: 25] <= {quo_i[23:0], ge};
            q_side[13*k +: 13] <= side_i;
        end
    end
endgenerate

// ---------------------------------------------------------------- stage 28
// Q[24:1] = significand, Q[0] = guard, sticky = remainder != 0; biased exponent
// e. If e < 1 the result is subnormal: shift Q right by 1 - e (the shifted-out
// bits join the sticky) and pack with e = 1. A shift of 25 or more leaves only
// sticky: rounds to 0; 31 is plenty.
wire [24:0] qf   = q_quo [25*(NQ-1) +: 25];
wire        qst  = |q_rem[25*(NQ-1) +: 25];
wire [12:0] qsd  = q_side[13*(NQ-1) +: 13];
wire [1:0]  spcq = qsd[12:11];
wire        sgq  = qsd[10];
wire [9:0]  eq   = qsd[9:0];
wire        subq = eq[9] | (eq == 10'd0);           // e <= 0
wire [9:0]  ds   = 10'd1 - eq;
wire [4:0]  shq  = !subq ? 5'd0 : (ds > 10'd31) ? 5'd31 : ds[4:0];
wire [24:0] dq   = qf >> shq;
wire        lost = |(qf & ~({25{1'b1}} << shq));    // bits shifted out
wire [9:0]  epq  = subq ? 10'd1 : (eq > 10'd255) ? 10'd255 : eq;   // 255: overflow
wire [30:0] mag  = rnd_pack(epq, dq[24:1], dq[0], qst | lost);
`UNIT_REG
    r <= (spcq == 2'd3) ? QNAN :
         (spcq == 2'd2) ? {sgq, 31'h7F800000} :
         (spcq == 2'd1) ? {sgq, 31'd0} :
                          {sgq, mag};

endmodule
