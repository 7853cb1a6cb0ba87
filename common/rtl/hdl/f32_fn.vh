// f32_fn.vh -- combinational helpers on IEEE-754 binary32 bit patterns, as plain
// Verilog-2005 functions: `include inside a module body. They match Rust's
// f32::is_nan, f32::is_finite, `>`, `<`, f32::abs and `-x` (negation is a sign
// flip on every value, NaN included, as on x86-64).

// NaN: exponent all ones and a non-zero fraction (quiet or signalling).
function f32_is_nan;
    input [31:0] a;
    begin
        f32_is_nan = (a[30:23] == 8'hFF) && (a[22:0] != 23'd0);
    end
endfunction

// Finite: not +-inf and not NaN (zeros and subnormals are finite).
function f32_is_finite;
    input [31:0] a;
    begin
        f32_is_finite = (a[30:23] != 8'hFF);
    end
endfunction

// a > b, IEEE ordered: 0 if either is NaN; +0 and -0 compare equal. For the rest
// the bit patterns order like sign-magnitude integers.
function f32_gt;
    input [31:0] a;
    input [31:0] b;
    begin
        if (f32_is_nan(a) || f32_is_nan(b) || (a[30:0] == 31'd0 && b[30:0] == 31'd0))
            f32_gt = 1'b0;
        else case ({a[31], b[31]})
            2'b00:   f32_gt = a[30:0] > b[30:0];    // both positive
            2'b01:   f32_gt = 1'b1;                 // a >= +0 > b (not both zero)
            2'b10:   f32_gt = 1'b0;                 // a <= -0 < b
            default: f32_gt = a[30:0] < b[30:0];    // both negative
        endcase
    end
endfunction

// a < b, IEEE ordered (same rules as f32_gt).
function f32_lt;
    input [31:0] a;
    input [31:0] b;
    begin
        f32_lt = f32_gt(b, a);
    end
endfunction

// |a|: clear the sign bit (NaN stays NaN).
function [31:0] f32_abs;
    input [31:0] a;
    begin
        f32_abs = {1'b0, a[30:0]};
    end
endfunction

// -a: flip the sign bit.
function [31:0] f32_neg;
    input [31:0] a;
    begin
        f32_neg = {~a[31], a[30:0]};
    end
endfunction
