// kin_sincos3: the three sines and cosines FK-HMD, FK-HSD and KFF-HMD start from,
// three tfb_sincos side by side in the format of tfb_params.vh.
// One new (t1, t2, t3) a clock; s1 .. c3 and range_err (any of the three angles
// beyond the TFB's range) appear tfb_sincos's LATENCY later (TFB_SINCOS_LAT in
// f32_lat.vh: ITER + 5 clocks in the pipeline "sample").
module kin_sincos3 (
    input  wire        clk,
    input  wire        in_valid,
    input  wire [31:0] t1, t2, t3,
    output wire [31:0] s1, c1, s2, c2, s3, c3,
    output wire        range_err
);
    `include "tfb_params.vh"

    wire [95:0] t = {t1, t2, t3};
    wire [2:0]  r;
    wire [95:0] s, c;
    genvar i;
    generate
        for (i = 0; i < 3; i = i + 1) begin : tfb
            tfb_sincos #(
                .WORD(WORD), .FRAC(FRAC), .ITER(ITER), .NEAREST(NEAREST),
                .GUARD(GUARD), .GAIN(GAIN), .PI_Q(PI_Q), .HALF_PI_Q(HALF_PI_Q),
                .ATAN(ATAN), .TWO_PI(TWO_PI), .PI_UP(PI_UP),
                .THREE_PI_UP(THREE_PI_UP)
            ) u (
                .clk(clk), .in_valid(in_valid), .angle(t[95 - 32 * i -: 32]),
                .out_valid(), .sin_out(s[95 - 32 * i -: 32]),
                .cos_out(c[95 - 32 * i -: 32]), .range_err(r[2 - i]), .dbg_code(),
                .dbg_folded(), .dbg_flip(), .dbg_sin(), .dbg_cos()
            );
        end
    endgenerate
    assign {s1, s2, s3} = s;
    assign {c1, c2, c3} = c;
    assign range_err = |r;
endmodule
