// A W-bit delay line of N clocks (N = 0: a wire). Lines up flags and the
// stage-boundary taps with the TFB's outputs. One always block per stage (rather
// than a for loop of non-blocking assignments to an array, which Verilator 5.006
// does not take), the same registers for synthesis.
module tfb_delay #(
    parameter integer W = 1,
    parameter integer N = 1
) (
    input  wire         clk,
    input  wire [W-1:0] d,
    output wire [W-1:0] q
);
    generate
        if (N == 0) begin : wire_through
            assign q = d;
        end else begin : line
            reg [W-1:0] r [0:N-1];
            always @(posedge clk)
                r[0] <= d;
            genvar i;
            for (i = 1; i < N; i = i + 1) begin : stage
                always @(posedge clk)
                    r[i] <= r[i-1];
            end
            assign q = r[N-1];
        end
    endgenerate
endmodule
