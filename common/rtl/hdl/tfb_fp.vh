// FP2F and the f32 helpers of F2FP, shared by the TFB's modules (included inside
// each module, so they are plain Verilog-2005 functions).

// FP2F: the f32 nearest to v * 2^-scale, ties to even: Rust's `v as f32 * 2^-scale`
// (the product by a power of two is exact for every code here). v = 0 gives +0.0.
// FP2F_W, the code's width, is a localparam of the including module.
function [31:0] fp2f;
    input signed [FP2F_W-1:0] v;
    input integer scale;
    reg [FP2F_W:0] m;
    reg [FP2F_W+24:0] r;
    reg [24:0] mant;
    reg g, st;
    integer p, i, ex;
    begin
        m = v[FP2F_W-1] ? -{v[FP2F_W-1], v} : {1'b0, v};
        p = 0;
        for (i = 0; i <= FP2F_W; i = i + 1)
            if (m[i]) p = i;
        if (p <= 23) begin
            r = {{24{1'b0}}, m} << (23 - p);
            mant = {1'b0, r[23:0]};
            g = 1'b0;
            st = 1'b0;
        end else begin
            r = {{24{1'b0}}, m} >> (p - 24);   // 24 significant bits and the guard bit
            mant = {1'b0, r[24:1]};
            g = r[0];
            st = |(m & ~({(FP2F_W+1){1'b1}} << (p - 24)));
        end
        if (g && (st || mant[0])) mant = mant + 25'd1;
        if (mant[24]) begin                    // rounding carried into a new bit
            mant = mant >> 1;
            p = p + 1;
        end
        ex = p - scale + 127;
        fp2f = (m == 0) ? 32'd0 : {v[FP2F_W-1], ex[7:0], mant[22:0]};
    end
endfunction

// The significand of an f32 with its leading one at bit 23 (subnormals normalised),
// 0 for zero.
function [23:0] f32_sig;
    input [31:0] f;
    integer i, p;
    begin
        p = -1;
        for (i = 0; i < 23; i = i + 1)
            if (f[i]) p = i;
        if (f[30:23] != 8'd0)
            f32_sig = {1'b1, f[22:0]};
        else if (p < 0)
            f32_sig = 24'd0;
        else
            f32_sig = {1'b0, f[22:0]} << (23 - p);
    end
endfunction

// The exponent e of that significand: |f| = sig * 2^(e - 23); -150 for zero.
function integer f32_exp;
    input [31:0] f;
    integer i, p;
    begin
        p = -1;
        for (i = 0; i < 23; i = i + 1)
            if (f[i]) p = i;
        if (f[30:23] != 8'd0)
            f32_exp = f[30:23] - 127;
        else if (p < 0)
            f32_exp = -150;
        else
            f32_exp = p - 149;
    end
endfunction
