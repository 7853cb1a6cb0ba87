// Co-simulation testbench of the paper's modules (kin_fk, kin_kff, kin_fbf, kin_ik):
// feeds one vector a clock (from `tactile hdl vectors --function fk|kff|fbf|ik`) and
// compares every output and every dbg tap bit for bit (f32: equal bits, or both NaN
// with any payload).
// Define MOD_FK, MOD_KFF, MOD_FBF or MOD_IK; plusargs +vectors=FILE +count=N.
// The file is read by $readmemh into 64-bit words: one vector a line, one word a field
// (comment lines start with //), fields in this order:
//   fk:  t1 t2 t3 err s1 c1 s2 c2 s3 c3 x y z
//   kff: t1 t2 t3 f1 f2 f3 err s1 c1 s2 c2 s3 c3 j11 j12 j13 j21 j22 j23 j31 j32 j33
//        tau1 tau2 tau3
//   fbf: o1 o2 o3 e1 e2 e3 h1 h2 h3 d1 d2 d3 f1 f2 f3
//   ik:  x y z status xs ys zs atan rr2 big_r r2 r cg gamma beta ca alpha t1 t2 t3
// err = 1 (fk, kff): only err is compared. status = 2 (ik): only status and t1..t3.
// The first 5 mismatching vectors are printed with the fields that differ; the last
// line is "kin-cosim: <fk|kff|fbf|ik> vectors=<n> mismatches=<m>".
// +dump=FILE (optional) writes what the RTL gave, one vector a line, every field in
// the same order (the inputs as read).
`timescale 1ns / 1ps
`ifdef MOD_FK
`define MOD_NAME "fk"
`elsif MOD_KFF
`define MOD_NAME "kff"
`elsif MOD_FBF
`define MOD_NAME "fbf"
`elsif MOD_IK
`define MOD_NAME "ik"
`else
`define MOD_FK
`define MOD_NAME "fk"
`endif
module tb;
`ifdef MOD_FK
    localparam integer F = 13;      // fields a vector
    localparam integer NI = 3;      // inputs, the first fields
    localparam integer FLAG = 3;    // err
`elsif MOD_KFF
    localparam integer F = 25;
    localparam integer NI = 6;
    localparam integer FLAG = 6;    // err
`elsif MOD_FBF
    localparam integer F = 15;
    localparam integer NI = 9;
    localparam integer FLAG = -1;   // none
`else
    localparam integer F = 20;
    localparam integer NI = 3;
    localparam integer FLAG = 3;    // status
`endif
`ifndef MAXWORDS
    `define MAXWORDS (1 << 22)
`endif
    reg [63:0] mem [0:`MAXWORDS-1];
    reg [8*4096-1:0] path, dump_path;
    integer dump;
    integer latency = -1;   // clocks from the first input to the first output
    integer count, n_in, n_out, bad, cycles, i, j, nf;
    reg clk = 1'b0;
    reg in_valid = 1'b0;
    reg [32*9-1:0] in = {(32*9){1'b0}};     // field i at [32 i +: 32]
    wire out_valid;
    reg [32*F-1:0] got;                     // field i at [32 i +: 32]

    // The field names, in file order.
    function [8*6-1:0] fname;
        input integer k;
        begin
            fname = "?";
`ifdef MOD_FK
            case (k)
                0: fname = "t1";  1: fname = "t2";  2: fname = "t3";  3: fname = "err";
                4: fname = "s1";  5: fname = "c1";  6: fname = "s2";  7: fname = "c2";
                8: fname = "s3";  9: fname = "c3";  10: fname = "x";  11: fname = "y";
                12: fname = "z";
            endcase
`elsif MOD_KFF
            case (k)
                0: fname = "t1";  1: fname = "t2";  2: fname = "t3";  3: fname = "f1";
                4: fname = "f2";  5: fname = "f3";  6: fname = "err"; 7: fname = "s1";
                8: fname = "c1";  9: fname = "s2";  10: fname = "c2"; 11: fname = "s3";
                12: fname = "c3"; 13: fname = "j11"; 14: fname = "j12"; 15: fname = "j13";
                16: fname = "j21"; 17: fname = "j22"; 18: fname = "j23"; 19: fname = "j31";
                20: fname = "j32"; 21: fname = "j33"; 22: fname = "tau1"; 23: fname = "tau2";
                24: fname = "tau3";
            endcase
`elsif MOD_FBF
            case (k)
                0: fname = "o1";  1: fname = "o2";  2: fname = "o3";  3: fname = "e1";
                4: fname = "e2";  5: fname = "e3";  6: fname = "h1";  7: fname = "h2";
                8: fname = "h3";  9: fname = "d1";  10: fname = "d2"; 11: fname = "d3";
                12: fname = "f1"; 13: fname = "f2"; 14: fname = "f3";
            endcase
`else
            case (k)
                0: fname = "x";   1: fname = "y";   2: fname = "z";   3: fname = "status";
                4: fname = "xs";  5: fname = "ys";  6: fname = "zs";  7: fname = "atan";
                8: fname = "rr2"; 9: fname = "big_r"; 10: fname = "r2"; 11: fname = "r";
                12: fname = "cg"; 13: fname = "gamma"; 14: fname = "beta"; 15: fname = "ca";
                16: fname = "alpha"; 17: fname = "t1"; 18: fname = "t2"; 19: fname = "t3";
            endcase
`endif
        end
    endfunction

    function is_nan;
        input [31:0] v;
        is_nan = v[30:23] == 8'hFF && v[22:0] != 23'd0;
    endfunction

    // Whether field k of the vector at base b is compared, and whether it matches.
    function compared;
        input integer k;
        input integer b;
        reg [63:0] flag;
        begin
            compared = k >= NI;
            if (FLAG >= 0) begin
                flag = mem[b + FLAG];
`ifdef MOD_IK
                if (flag[3:0] == 4'd2) compared = k == FLAG || k >= 17;
`else
                if (flag[3:0] == 4'd1) compared = k == FLAG;
`endif
            end
        end
    endfunction
    function matches;
        input integer k;
        input [63:0] e;
        input [31:0] g;
        begin
            if (k == FLAG)
                matches = e == {32'd0, g};
            else
                matches = e[31:0] == g || (is_nan(e[31:0]) && is_nan(g));
        end
    endfunction

    initial begin
        if (!$value$plusargs("vectors=%s", path) || !$value$plusargs("count=%d", count)) begin
            $display("kin-cosim: usage: +vectors=FILE +count=N");
            $finish;
        end
        if (count * F > `MAXWORDS) begin
            $display("kin-cosim: too many vectors for MAXWORDS");
            $finish;
        end
        $readmemh(path, mem, 0, count * F - 1);
        // A file $readmemh could not read leaves X, and X compares as no mismatch:
        // fail instead of passing on nothing.
        if (^mem[0] === 1'bx) begin
            $display("kin-cosim: cannot read the vectors from %0s", path);
            $finish;
        end
        dump = 0;
        if ($value$plusargs("dump=%s", dump_path))
            dump = $fopen(dump_path, "w");
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
            for (i = 0; i < NI; i = i + 1)
                in[32*i +: 32] <= mem[n_in * F + i][31:0];
            in_valid <= 1'b1;
            n_in <= n_in + 1;
        end else
            in_valid <= 1'b0;
        if (cycles > count + 5000) begin
            $display("kin-cosim: timeout after %0d outputs", n_out);
            $display("kin-cosim: %s vectors=%0d mismatches=%0d", `MOD_NAME, n_out, bad + count - n_out);
            $finish;
        end
    end

    always @(posedge clk)
        if (out_valid) begin
            nf = 0;
            for (i = 0; i < F; i = i + 1)
                if (compared(i, n_out * F) && !matches(i, mem[n_out * F + i], got[32*i +: 32]))
                    nf = nf + 1;
            if (nf > 0) begin
                if (bad < 5) begin
                    $write("kin-cosim: mismatch at vector %0d, inputs", n_out);
                    for (i = 0; i < NI; i = i + 1)
                        $write(" %0s=%h", fname(i), mem[n_out * F + i][31:0]);
                    $write("\n");
                    for (i = 0; i < F; i = i + 1)
                        if (compared(i, n_out * F) && !matches(i, mem[n_out * F + i], got[32*i +: 32]))
                            $display("kin-cosim:   %0s expected %h got %h", fname(i),
                                     mem[n_out * F + i][31:0], got[32*i +: 32]);
                end
                bad = bad + 1;
            end
            if (dump != 0) begin
                for (i = 0; i < F; i = i + 1)
                    if (i < NI)
                        $fwrite(dump, "%h ", mem[n_out * F + i][31:0]);
                    else
                        $fwrite(dump, "%h ", got[32*i +: 32]);
                $fwrite(dump, "\n");
            end
            n_out = n_out + 1;
            if (n_out == count) begin
                if (dump != 0) $fclose(dump);
                $display("kin-cosim: %s vectors=%0d mismatches=%0d latency=%0d", `MOD_NAME, count, bad, latency);
                $finish;
            end
        end

`ifdef MOD_FK
    wire [31:0] x, y, z;
    wire err;
    wire [191:0] dbg;
    kin_fk dut (
        .clk(clk), .in_valid(in_valid), .t1(in[0 +: 32]), .t2(in[32 +: 32]), .t3(in[64 +: 32]),
        .out_valid(out_valid), .x(x), .y(y), .z(z), .err(err), .dbg(dbg)
    );
    always @* begin
        got = {(32*F){1'b0}};
        got[32*3 +: 32] = {31'd0, err};
        for (j = 0; j < 6; j = j + 1)
            got[32*(4+j) +: 32] = dbg[32*(5-j) +: 32];
        got[32*10 +: 96] = {z, y, x};
    end
`elsif MOD_KFF
    wire [31:0] tau1, tau2, tau3;
    wire err;
    wire [32*15-1:0] dbg;
    kin_kff dut (
        .clk(clk), .in_valid(in_valid), .t1(in[0 +: 32]), .t2(in[32 +: 32]), .t3(in[64 +: 32]),
        .f1(in[96 +: 32]), .f2(in[128 +: 32]), .f3(in[160 +: 32]),
        .out_valid(out_valid), .tau1(tau1), .tau2(tau2), .tau3(tau3), .err(err), .dbg(dbg)
    );
    always @* begin
        got = {(32*F){1'b0}};
        got[32*6 +: 32] = {31'd0, err};
        for (j = 0; j < 15; j = j + 1)
            got[32*(7+j) +: 32] = dbg[32*(14-j) +: 32];
        got[32*22 +: 96] = {tau3, tau2, tau1};
    end
`elsif MOD_FBF
    wire [31:0] f1, f2, f3;
    wire [95:0] dbg;
    kin_fbf dut (
        .clk(clk), .in_valid(in_valid),
        .o1(in[0 +: 32]), .o2(in[32 +: 32]), .o3(in[64 +: 32]),
        .e1(in[96 +: 32]), .e2(in[128 +: 32]), .e3(in[160 +: 32]),
        .h1(in[192 +: 32]), .h2(in[224 +: 32]), .h3(in[256 +: 32]),
        .out_valid(out_valid), .f1(f1), .f2(f2), .f3(f3), .dbg(dbg)
    );
    always @* begin
        got = {(32*F){1'b0}};
        got[32*9 +: 32] = dbg[95:64];
        got[32*10 +: 32] = dbg[63:32];
        got[32*11 +: 32] = dbg[31:0];
        got[32*12 +: 96] = {f3, f2, f1};
    end
`else
    wire [31:0] t1, t2, t3;
    wire [1:0] status;
    wire [32*13-1:0] dbg;
    kin_ik dut (
        .clk(clk), .in_valid(in_valid), .x(in[0 +: 32]), .y(in[32 +: 32]), .z(in[64 +: 32]),
        .out_valid(out_valid), .t1(t1), .t2(t2), .t3(t3), .status(status), .dbg(dbg)
    );
    always @* begin
        got = {(32*F){1'b0}};
        got[32*3 +: 32] = {30'd0, status};
        for (j = 0; j < 13; j = j + 1)
            got[32*(4+j) +: 32] = dbg[32*(12-j) +: 32];
        got[32*17 +: 96] = {t3, t2, t1};
    end
`endif
endmodule
