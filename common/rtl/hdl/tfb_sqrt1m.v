// tfb_sqrt1m: fully pipelined binary32 datapath, bit-exact with the Rust f32 code
//     let a = a.clamp(-1.0, 1.0);
//     let s = ((1.0 - a) * (1.0 + a)).sqrt();
// Every operation rounds to nearest-even exactly once, as IEEE f32 does.
// a must not be NaN (caller handles NaN); +-inf and huge values clamp to +-1.
// One new a per clock; s and a_clamp appear LATENCY clocks later (LATENCY
// register stages from port a to ports s / a_clamp). No reset: pure datapath.
//
// Stage map (LATENCY = TFB_SQRT1M_LAT in f32_lat.vh: 33 with every stage a register,
// pipeline "sample"; stage 33 is the output register, `UNIT_REG, the others
// `STAGE_REG, each a register or a wire as pipe.vh says):
//   1      clamp
//   2-4    u = fl(1-a), v = fl(1+a): exact fixed-point add, normalize, round
//   5-7    p = fl(u*v): operand->product reg, product pipe reg (DSP MREG/PREG), round
//   8-32   25 restoring square-root digit stages (24 result bits + guard)
//   33     round sqrt, pack s
module tfb_sqrt1m (
    input  wire        clk,
    input  wire [31:0] a,        // f32 bits
    output reg  [31:0] s,        // f32 bits of sqrt((1-a)(1+a))
    output reg  [31:0] a_clamp   // f32 bits of clamp(a,-1,1), aligned with s
);
`include "f32_lat.vh"
localparam NQ      = 25;         // sqrt digit stages (24 significant bits + guard)

// Round-to-nearest-even of a 24-bit significand (hidden bit set) with guard g
// and sticky st; a carry out of the significand bumps the exponent.
// Returns {exp[7:0], significand[23:0]}.
function [31:0] rne;
    input [7:0]  e;
    input [23:0] m;
    input        g;
    input        st;
    reg   [24:0] r;
    begin
        r   = {1'b0, m} + {24'd0, g & (st | m[0])};
        rne = r[24] ? {e + 8'd1, 24'h800000} : {e, r[23:0]};
    end
endfunction

// Leading-zero count of a 51-bit word (51 when zero).
function [5:0] lzc51;
    input [50:0] x;
    integer i;
    begin
        lzc51 = 6'd51;
        for (i = 0; i < 51; i = i + 1)
            if (x[i]) lzc51 = 6'd50 - i[5:0];
    end
endfunction

// ---------------------------------------------------------------- stage 1
// Clamp: |a| >= 1 (exponent >= 127, includes inf) becomes +-1.0; else a
// unchanged (so -0.0 stays -0.0).
reg [31:0] c1;
`STAGE_REG
    c1 <= (a[30:23] >= 8'd127) ? {a[31], 8'd127, 23'd0} : a;

// ---------------------------------------------------------------- stage 2
// 1 -+ |a| in fixed point with 49 fraction bits (bit 49 = 1.0). Every |a| >=
// 2^-26 (biased exp >= 101) is exact there. Smaller |a| (incl. subnormals and
// zeros) are dropped: 1 +- x with |x| < 2^-26 always rounds to exactly 1.0
// (half-ulp is 2^-24 above 1 and 2^-25 below 1), which X = 0 yields.
wire [7:0]  c1_e  = c1[30:23];
wire [23:0] c1_m  = {|c1_e, c1[22:0]};
wire [7:0]  c1_sh = c1_e - 8'd101;               // 0..26 when c1_e >= 101
wire [49:0] c1_x  = (c1_e < 8'd101) ? 50'd0 : ({26'd0, c1_m} << c1_sh[4:0]);
wire [50:0] one   = {2'b01, 49'd0};
wire [50:0] c1_sp = one + {1'b0, c1_x};          // 1 + |a|, <= 2
wire [50:0] c1_sm = one - {1'b0, c1_x};          // 1 - |a|, >= 0 (|a| <= 1)
reg  [50:0] su2, sv2;
`STAGE_REG begin
    su2 <= c1[31] ? c1_sp : c1_sm;               // 1 - a
    sv2 <= c1[31] ? c1_sm : c1_sp;               // 1 + a
end

// ---------------------------------------------------------------- stage 3
// Normalize: leading one to bit 50. Value = n * 2^(e-127-50), e = 128 - lz.
wire [5:0] lzu = lzc51(su2);
wire [5:0] lzv = lzc51(sv2);
reg  [50:0] nu3, nv3;
reg  [7:0]  eu3, ev3;
reg         zu3, zv3;
`STAGE_REG begin
    nu3 <= su2 << lzu;
    nv3 <= sv2 << lzv;
    eu3 <= 8'd128 - {2'b00, lzu};
    ev3 <= 8'd128 - {2'b00, lzv};
    zu3 <= (su2 == 51'd0);                       // exact zero -> +0.0
    zv3 <= (sv2 == 51'd0);
end

// ---------------------------------------------------------------- stage 4
// Round u and v to 24 bits (sum is exact, so guard/sticky are exact).
reg [31:0] u4, v4;                               // {exp, significand}
reg        zu4, zv4;
`STAGE_REG begin
    u4  <= rne(eu3, nu3[50:27], nu3[26], |nu3[25:0]);
    v4  <= rne(ev3, nv3[50:27], nv3[26], |nv3[25:0]);
    zu4 <= zu3;
    zv4 <= zv3;
end

// ---------------------------------------------------------------- stages 5-6
// 24x24 significand product. Nonzero u, v are >= 2^-24, so p is normal.
reg [47:0] pm5, pm6;
reg [8:0]  pe5, pe6;                             // eu + ev - 127
reg        pz5, pz6;
`STAGE_REG begin
    pm5 <= u4[23:0] * v4[23:0];
    pe5 <= {1'b0, u4[31:24]} + {1'b0, v4[31:24]} - 9'd127;
    pz5 <= zu4 | zv4;
    pm6 <= pm5;
    pe6 <= pe5;
    pz6 <= pz5;
end

// ---------------------------------------------------------------- stage 7
// Normalize product (in [2^46, 2^48)) and round.
reg [31:0] p7;                                   // {exp, significand}
reg        pz7;
`STAGE_REG begin
    p7  <= pm6[47] ? rne(pe6[7:0] + 8'd1, pm6[47:24], pm6[23], |pm6[22:0])
                   : rne(pe6[7:0],        pm6[46:23], pm6[22], |pm6[21:0]);
    pz7 <= pz6;
end

// ---------------------------------------------------------------- stages 8-32
// sqrt(m * 2^(E-23)), E unbiased. Make the exponent even: with E odd (biased
// exp even) use 2m. Radicand R = m*2^25 (E even) or m*2^26 (E odd) so that
// Q = isqrt(R) has 1 integer + 24 fraction bits; result exponent is
// floor(E/2), biased (Ep + 126 + Ep[0]) / 2.
wire [7:0]  p7_e   = p7[31:24];
wire [49:0] r0_rad = p7_e[0] ? {1'b0, p7[23:0], 25'd0} : {p7[23:0], 26'd0};
wire [8:0]  r0_exp = ({1'b0, p7_e} + 9'd126 + {8'd0, p7_e[0]}) >> 1;

// Flat buses between stages (slice k = output register of digit stage k).
reg [50*NQ-1:0] q_rad /*verilator split_var*/;                           // radicand, consumed 2 bits/stage
reg [26*NQ-1:0] q_rem /*verilator split_var*/;                           // partial remainder (< 2^26)
reg [25*NQ-1:0] q_root /*verilator split_var*/;                          // partial root
reg [9*NQ-1:0]  q_side /*verilator split_var*/;                          // {zero, result exponent}

genvar k;
generate
    for (k = 0; k < NQ; k = k + 1) begin : sq
        wire [49:0] rad_i;
        wire [25:0] rem_i;
        wire [24:0] root_i;
        wire [8:0]  side_i;
        if (k == 0) begin : first
            assign rad_i  = r0_rad;
            assign rem_i  = 26'd0;
            assign root_i = 25'd0;
            assign side_i = {pz7, r0_exp[7:0]};
        end else begin : next
            assign rad_i  = q_rad [50*(k-1) +: 50];
            assign rem_i  = q_rem [26*(k-1) +: 26];
            assign root_i = q_root[25*(k-1) +: 25];
            assign side_i = q_side[9*(k-1)  +: 9];
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
            q_side[9*k  +: 9]  <= side_i;
        end
    end
endgenerate

// ---------------------------------------------------------------- stage 33
// Q[24:1] = significand, Q[0] = guard, sticky = remainder != 0.
wire [24:0] qf   = q_root[25*(NQ-1) +: 25];
wire        qst  = |q_rem[26*(NQ-1) +: 26];
wire [8:0]  qsd  = q_side[9*(NQ-1) +: 9];
wire [31:0] qr   = rne(qsd[7:0], qf[24:1], qf[0], qst);
`UNIT_REG
    s <= qsd[8] ? 32'd0 : {1'b0, qr[31:24], qr[22:0]};

// a_clamp: c1 delayed to line up with s (stages 2-32, then the output register).
wire [31:0] ac_dly;
tfb_delay #(.W(32), .N(31 * PIPE_S)) d_ac (.clk(clk), .d(c1), .q(ac_dly));
`UNIT_REG
    a_clamp <= ac_dly;

endmodule
