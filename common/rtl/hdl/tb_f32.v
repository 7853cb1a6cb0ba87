// Co-simulation testbench of the f32 units: feeds one vector a clock into one unit
// and compares its output, LATENCY clocks later, with the expected f32.
// Define OP_ADD, OP_SUB, OP_MUL, OP_DIV or OP_SQRT; plusargs +vectors=FILE +count=N.
// The file ($readmemh, `//` comments allowed) has one vector a line of 8-hex-digit
// f32 bit patterns: `a b r` (sqrt: `a r`).
// A result matches if its bits are equal, or if both are NaN: the units return
// the canonical quiet NaN, while NaN payloads are not defined by IEEE (and Rust /
// LLVM may swap the operands of commutative ops).
// Last line: "f32-cosim: <op> vectors=<n> mismatches=<m>".
`timescale 1ns / 1ps
`ifdef OP_ADD
`define OP_NAME "add"
`elsif OP_SUB
`define OP_NAME "sub"
`elsif OP_MUL
`define OP_NAME "mul"
`elsif OP_DIV
`define OP_NAME "div"
`elsif OP_SQRT
`define OP_NAME "sqrt"
`else
`define OP_NAME "add"
`define OP_ADD
`endif
module tb;
    `include "f32_lat.vh"
    `include "f32_fn.vh"
`ifdef OP_SQRT
    localparam integer F = 2;        // a r
    localparam integer LAT = F32_SQRT_LAT;
`else
    localparam integer F = 3;        // a b r
`ifdef OP_MUL
    localparam integer LAT = F32_MUL_LAT;
`elsif OP_DIV
    localparam integer LAT = F32_DIV_LAT;
`else
    localparam integer LAT = F32_ADD_LAT;
`endif
`endif
`ifndef MAXWORDS
    `define MAXWORDS (1 << 22)
`endif
    reg [63:0] mem [0:`MAXWORDS-1];
    reg [8*4096-1:0] path;
    integer count, n_in, n_out, bad, cycles;
    reg clk = 1'b0;
    reg [31:0] in_a = 32'd0, in_b = 32'd0;
    wire [31:0] r;

    initial begin
        if (!$value$plusargs("vectors=%s", path) || !$value$plusargs("count=%d", count)) begin
            $display("f32-cosim: usage: +vectors=FILE +count=N");
            $finish;
        end
        if (count < 1 || count * F > `MAXWORDS) begin
            $display("f32-cosim: count must be 1..MAXWORDS/%0d", F);
            $finish;
        end
        $readmemh(path, mem, 0, count * F - 1);
        // A file $readmemh could not read leaves X, and X compares as no mismatch:
        // fail instead of passing on nothing.
        if (^mem[0] === 1'bx) begin
            $display("f32-cosim: cannot read the vectors from %0s", path);
            $finish;
        end
        n_in = 0;
        n_out = 0;
        bad = 0;
        cycles = 0;
    end
    always #5 clk = ~clk;

`ifdef OP_ADD
    f32_add #(.SUB(0)) dut (.clk(clk), .a(in_a), .b(in_b), .r(r));
`elsif OP_SUB
    f32_add #(.SUB(1)) dut (.clk(clk), .a(in_a), .b(in_b), .r(r));
`elsif OP_MUL
    f32_mul dut (.clk(clk), .a(in_a), .b(in_b), .r(r));
`elsif OP_DIV
    f32_div dut (.clk(clk), .a(in_a), .b(in_b), .r(r));
`else
    f32_sqrt dut (.clk(clk), .a(in_a), .r(r));
`endif

    // Vector i is driven at the edge where cycles == i, enters the unit's first
    // register one edge later and reaches r at edge i + LAT; r is read (before
    // this edge's update) at edge i + LAT + 1.
    reg [31:0] e_a, e_b, e_r;
    always @(posedge clk) begin
        cycles <= cycles + 1;
        if (n_in < count) begin
            in_a <= mem[n_in * F][31:0];
            if (F == 3)
                in_b <= mem[n_in * F + 1][31:0];
            n_in <= n_in + 1;
        end
        if (cycles > LAT) begin
            e_a = mem[n_out * F][31:0];
            e_b = mem[n_out * F + 1][31:0];             // sqrt: not used
            e_r = mem[n_out * F + F - 1][31:0];
            if (!(r == e_r || (f32_is_nan(r) && f32_is_nan(e_r)))) begin
                if (bad < 5) begin
                    if (F == 3)
                        $display("f32-cosim: mismatch at vector %0d: a=%h b=%h expected %h got %h",
                                 n_out, e_a, e_b, e_r, r);
                    else
                        $display("f32-cosim: mismatch at vector %0d: a=%h expected %h got %h",
                                 n_out, e_a, e_r, r);
                end
                bad = bad + 1;
            end
            n_out = n_out + 1;
            if (n_out == count) begin
                $display("f32-cosim: %s vectors=%0d mismatches=%0d", `OP_NAME, count, bad);
                $finish;
            end
        end
    end
endmodule
