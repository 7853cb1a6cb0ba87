// A W-bit delay line of N clocks (N = 0: a wire). Lines up flags and the
// stage-boundary taps with the TFB's outputs.
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
            integer i;
            always @(posedge clk) begin
                r[0] <= d;
                for (i = 1; i < N; i = i + 1)
                    r[i] <= r[i-1];
            end
            assign q = r[N-1];
        end
    endgenerate
endmodule
