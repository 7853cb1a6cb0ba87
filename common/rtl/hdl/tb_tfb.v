// Co-simulation testbench: feeds one vector a clock (from `tactile hdl vectors`) into
// one TFB function and compares every output and stage tap bit for bit.
// Define FUNC_SINCOS, FUNC_ATAN2 or FUNC_ACOS; plusargs +vectors=FILE +count=N.
// Last line: "tfb-cosim: <function> vectors=<n> mismatches=<m>".
`timescale 1ns / 1ps
`ifdef FUNC_SINCOS
`define FUNC_NAME "sincos"
`elsif FUNC_ATAN2
`define FUNC_NAME "atan2"
`else
`define FUNC_NAME "acos"
`endif
module tb;
    `include "tfb_params.vh"
`ifdef FUNC_SINCOS
    localparam integer F = 9;       // angle err code folded flip sin_code cos_code sin cos
`else
    localparam integer F = 7;       // atan2: y x stages xc yc zc out; acos: a stages root xc yc zc out
`endif
`ifndef MAXWORDS
    `define MAXWORDS (1 << 22)
`endif
    reg [63:0] mem [0:`MAXWORDS-1];
    reg [8*4096-1:0] path;
    integer latency = -1;   // clocks from the first input to the first output
    integer count, n_in, n_out, bad, cycles;
    reg clk = 1'b0;
    reg in_valid = 1'b0;
    reg [31:0] in0 = 32'd0, in1 = 32'd0;
    wire out_valid;
    wire [WORD-1:0] m = {WORD{1'b1}};

    initial begin
        if (!$value$plusargs("vectors=%s", path) || !$value$plusargs("count=%d", count)) begin
            $display("tfb-cosim: usage: +vectors=FILE +count=N");
            $finish;
        end
        if (count * F > `MAXWORDS) begin
            $display("tfb-cosim: too many vectors for MAXWORDS");
            $finish;
        end
        $readmemh(path, mem, 0, count * F - 1);
        // A file $readmemh could not read leaves X, and X compares as no mismatch:
        // fail instead of passing on nothing.
        if (^mem[0] === 1'bx) begin
            $display("tfb-cosim: cannot read the vectors from %0s", path);
            $finish;
        end
        n_in = 0;
        n_out = 0;
        bad = 0;
        cycles = 0;
    end
    always #5 clk = ~clk;

    // The first input is driven at the edge where cycles == 0 and enters the first
    // register at the next; the first output is seen one edge after it is registered.
    always @(posedge clk)
        if (out_valid && latency < 0)
            latency = cycles - 1;

    always @(posedge clk) begin
        cycles <= cycles + 1;
        if (n_in < count) begin
            in0 <= mem[n_in * F][31:0];
            in1 <= mem[n_in * F + 1][31:0];
            in_valid <= 1'b1;
            n_in <= n_in + 1;
        end else
            in_valid <= 1'b0;
        if (cycles > count + 1000) begin
            $display("tfb-cosim: timeout after %0d outputs", n_out);
            $display("tfb-cosim: %s vectors=%0d mismatches=%0d", `FUNC_NAME, n_out, bad + count - n_out);
            $finish;
        end
    end

    task check;
        input ok;
        begin
            if (!ok) begin
                if (bad < 5)
                    $display("tfb-cosim: mismatch at vector %0d (input %h %h)", n_out,
                             mem[n_out * F][31:0], mem[n_out * F + 1][31:0]);
                bad = bad + 1;
            end
            n_out <= n_out + 1;
            if (n_out + 1 == count) begin
                $display("tfb-cosim: %s vectors=%0d mismatches=%0d latency=%0d", `FUNC_NAME, count, bad, latency);
                $finish;
            end
        end
    endtask

`ifdef FUNC_SINCOS
    wire [31:0] s, c;
    wire err, flip;
    wire [WORD-1:0] code, folded, sc, cc;
    tfb_sincos #(
        .WORD(WORD), .FRAC(FRAC), .ITER(ITER), .NEAREST(NEAREST), .GUARD(GUARD), .DEBUG(1),
        .GAIN(GAIN), .PI_Q(PI_Q), .HALF_PI_Q(HALF_PI_Q), .ATAN(ATAN), .TWO_PI(TWO_PI),
        .PI_UP(PI_UP), .THREE_PI_UP(THREE_PI_UP)
    ) dut (
        .clk(clk), .in_valid(in_valid), .angle(in0), .out_valid(out_valid),
        .sin_out(s), .cos_out(c), .range_err(err), .dbg_code(code), .dbg_folded(folded),
        .dbg_flip(flip), .dbg_sin(sc), .dbg_cos(cc)
    );
    wire [63:0] e_err = mem[n_out * F + 1];
    always @(posedge clk)
        if (out_valid)
            check(s == mem[n_out * F + 7][31:0] && c == mem[n_out * F + 8][31:0]
                  && err == e_err[0]
                  && (e_err[0] || (code == (mem[n_out * F + 2] & m)
                                   && folded == (mem[n_out * F + 3] & m)
                                   && flip == mem[n_out * F + 4][0]
                                   && sc == (mem[n_out * F + 5] & m)
                                   && cc == (mem[n_out * F + 6] & m))));
`else
    wire [31:0] out, root;
    wire [WORD-1:0] xc, yc, zc;
    wire [63:0] e_stages = mem[n_out * F + 2];
`ifdef FUNC_ATAN2
    assign root = 32'd0;
    tfb_atan2 #(
        .WORD(WORD), .FRAC(FRAC), .ITER(ITER), .NEAREST(NEAREST), .DEBUG(1),
        .PI_Q(PI_Q), .PI_FLOOR(PI_FLOOR), .ATAN(ATAN)
    ) dut (
        .clk(clk), .in_valid(in_valid), .y(in0), .x(in1), .out_valid(out_valid),
        .angle(out), .dbg_x(xc), .dbg_y(yc), .dbg_z(zc)
    );
    wire root_ok = 1'b1;
    wire [63:0] e_x = mem[n_out * F + 3], e_y = mem[n_out * F + 4], e_z = mem[n_out * F + 5];
`else
    tfb_acos #(
        .WORD(WORD), .FRAC(FRAC), .ITER(ITER), .NEAREST(NEAREST), .DEBUG(1),
        .PI_Q(PI_Q), .PI_FLOOR(PI_FLOOR), .ATAN(ATAN)
    ) dut (
        .clk(clk), .in_valid(in_valid), .a(in0), .out_valid(out_valid),
        .angle(out), .dbg_root(root), .dbg_x(xc), .dbg_y(yc), .dbg_z(zc)
    );
    wire root_ok = root == mem[n_out * F + 2][31:0];
    wire [63:0] e_stages_a = mem[n_out * F + 1];
    wire [63:0] e_x = mem[n_out * F + 3], e_y = mem[n_out * F + 4], e_z = mem[n_out * F + 5];
`endif
    always @(posedge clk)
        if (out_valid)
            check(out == mem[n_out * F + 6][31:0]
`ifdef FUNC_ACOS
                  && (!e_stages_a[0] || (root_ok
`else
                  && (!e_stages[0] || (root_ok
`endif
                      && xc == (e_x & m) && yc == (e_y & m) && zc == (e_z & m))));
`endif
endmodule
