// f32_round.vh: what the f32 units share, `include'd inside each unit's body
// (Verilog-2005 functions): the final rounding and packing, and a leading-zero count.

// Round {m, g, st} (24-bit significand, guard, sticky) to nearest even and pack
// the magnitude with biased exponent e (1..255; e >= 255 after rounding is
// inf). A significand without its leading one is subnormal (then e = 1) and packs
// with exponent field 0; rounding 0x7FFFFF up to 0x800000 makes it the least
// normal, and a carry out of 0xFFFFFF bumps e.
// F32_MUTANT_ROUND (test only): truncate instead, to show the co-simulation fails.
function [30:0] rnd_pack;
    input [9:0]  e;
    input [23:0] m;
    input        g;
    input        st;
    reg   [24:0] q;
    reg   [9:0]  ee;
    begin
`ifdef F32_MUTANT_ROUND
        q  = {1'b0, m};
`else
        q  = {1'b0, m} + {24'd0, g & (st | m[0])};
`endif
        ee = e + {9'd0, q[24]};
        if (q[24])
            q = q >> 1;                              // 0x1000000 -> 0x800000
        if (ee >= 10'd255)
            rnd_pack = {8'hFF, 23'd0};
        else
            rnd_pack = {q[23] ? ee[7:0] : 8'd0, q[22:0]};
    end
endfunction

// Leading-zero count of a 24-bit word (24 when zero).
function [4:0] lzc24;
    input [23:0] x;
    integer i;
    begin
        lzc24 = 5'd24;
        for (i = 0; i < 24; i = i + 1)
            if (x[i]) lzc24 = 5'd23 - i[4:0];
    end
endfunction
