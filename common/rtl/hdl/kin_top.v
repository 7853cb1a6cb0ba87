// Synthesis tops of the paper's modules, without the dbg taps (their delay lines are
// then unloaded and removed): top_fk (FK-HMD or FK-HSD), top_kff (KFF-HMD), top_fbf
// (FBF-HSD), top_ik (IK-HSD), and top_all holding the paper's five modules side by
// side, FK-HMD, KFF-HMD, FK-HSD, IK-HSD and FBF-HSD, each with its own ports. The
// format comes from tfb_params.vh, the geometry from kin_params.vh, the f32 units'
// latencies from f32_lat.vh (all included by the kin_* modules).
//   yosys -p 'read_verilog -I DIR DIR/kin_top.v DIR/kin_*.v DIR/tfb_*.v DIR/f32_*.v;
//             synth_xilinx -family xc6v -flatten -top top_fk; stat'
module top_fk (
    input  wire        clk,
    input  wire        in_valid,
    input  wire [31:0] t1, t2, t3,
    output wire        out_valid,
    output wire [31:0] x, y, z,
    output wire        err
);
    kin_fk u (
        .clk(clk), .in_valid(in_valid), .t1(t1), .t2(t2), .t3(t3),
        .out_valid(out_valid), .x(x), .y(y), .z(z), .err(err), .dbg()
    );
endmodule

module top_kff (
    input  wire        clk,
    input  wire        in_valid,
    input  wire [31:0] t1, t2, t3,
    input  wire [31:0] f1, f2, f3,
    output wire        out_valid,
    output wire [31:0] tau1, tau2, tau3,
    output wire        err
);
    kin_kff u (
        .clk(clk), .in_valid(in_valid), .t1(t1), .t2(t2), .t3(t3),
        .f1(f1), .f2(f2), .f3(f3), .out_valid(out_valid),
        .tau1(tau1), .tau2(tau2), .tau3(tau3), .err(err), .dbg()
    );
endmodule

module top_fbf (
    input  wire        clk,
    input  wire        in_valid,
    input  wire [31:0] o1, o2, o3,
    input  wire [31:0] e1, e2, e3,
    input  wire [31:0] h1, h2, h3,
    output wire        out_valid,
    output wire [31:0] f1, f2, f3
);
    kin_fbf u (
        .clk(clk), .in_valid(in_valid), .o1(o1), .o2(o2), .o3(o3),
        .e1(e1), .e2(e2), .e3(e3), .h1(h1), .h2(h2), .h3(h3),
        .out_valid(out_valid), .f1(f1), .f2(f2), .f3(f3), .dbg()
    );
endmodule

module top_ik (
    input  wire        clk,
    input  wire        in_valid,
    input  wire [31:0] x, y, z,
    output wire        out_valid,
    output wire [31:0] t1, t2, t3,
    output wire [1:0]  status
);
    kin_ik u (
        .clk(clk), .in_valid(in_valid), .x(x), .y(y), .z(z),
        .out_valid(out_valid), .t1(t1), .t2(t2), .t3(t3), .status(status), .dbg()
    );
endmodule

// The paper's five modules: on the master's side FK-HMD (joint angles theta^MD to the
// tool position c) and KFF-HMD (theta^MD and the force F^HSD to the torques tau^HMD);
// on the slave's side FK-HSD (theta^SD to the tool position in ENV), IK-HSD (the
// received position v to the reference angles theta^HSD) and FBF-HSD (object and
// tool positions, stiffness h, to the force F^HSD).
module top_all (
    input  wire        clk,
    // FK-HMD
    input  wire        fkm_in_valid,
    input  wire [31:0] fkm_t1, fkm_t2, fkm_t3,
    output wire        fkm_out_valid,
    output wire [31:0] fkm_x, fkm_y, fkm_z,
    output wire        fkm_err,
    // KFF-HMD
    input  wire        kff_in_valid,
    input  wire [31:0] kff_t1, kff_t2, kff_t3,
    input  wire [31:0] kff_f1, kff_f2, kff_f3,
    output wire        kff_out_valid,
    output wire [31:0] kff_tau1, kff_tau2, kff_tau3,
    output wire        kff_err,
    // FK-HSD
    input  wire        fks_in_valid,
    input  wire [31:0] fks_t1, fks_t2, fks_t3,
    output wire        fks_out_valid,
    output wire [31:0] fks_x, fks_y, fks_z,
    output wire        fks_err,
    // IK-HSD
    input  wire        ik_in_valid,
    input  wire [31:0] ik_x, ik_y, ik_z,
    output wire        ik_out_valid,
    output wire [31:0] ik_t1, ik_t2, ik_t3,
    output wire [1:0]  ik_status,
    // FBF-HSD
    input  wire        fbf_in_valid,
    input  wire [31:0] fbf_o1, fbf_o2, fbf_o3,
    input  wire [31:0] fbf_e1, fbf_e2, fbf_e3,
    input  wire [31:0] fbf_h1, fbf_h2, fbf_h3,
    output wire        fbf_out_valid,
    output wire [31:0] fbf_f1, fbf_f2, fbf_f3
);
    kin_fk fk_hmd (
        .clk(clk), .in_valid(fkm_in_valid), .t1(fkm_t1), .t2(fkm_t2), .t3(fkm_t3),
        .out_valid(fkm_out_valid), .x(fkm_x), .y(fkm_y), .z(fkm_z), .err(fkm_err), .dbg()
    );
    kin_kff kff_hmd (
        .clk(clk), .in_valid(kff_in_valid), .t1(kff_t1), .t2(kff_t2), .t3(kff_t3),
        .f1(kff_f1), .f2(kff_f2), .f3(kff_f3), .out_valid(kff_out_valid),
        .tau1(kff_tau1), .tau2(kff_tau2), .tau3(kff_tau3), .err(kff_err), .dbg()
    );
    kin_fk fk_hsd (
        .clk(clk), .in_valid(fks_in_valid), .t1(fks_t1), .t2(fks_t2), .t3(fks_t3),
        .out_valid(fks_out_valid), .x(fks_x), .y(fks_y), .z(fks_z), .err(fks_err), .dbg()
    );
    kin_ik ik_hsd (
        .clk(clk), .in_valid(ik_in_valid), .x(ik_x), .y(ik_y), .z(ik_z),
        .out_valid(ik_out_valid), .t1(ik_t1), .t2(ik_t2), .t3(ik_t3), .status(ik_status),
        .dbg()
    );
    kin_fbf fbf_hsd (
        .clk(clk), .in_valid(fbf_in_valid), .o1(fbf_o1), .o2(fbf_o2), .o3(fbf_o3),
        .e1(fbf_e1), .e2(fbf_e2), .e3(fbf_e3), .h1(fbf_h1), .h2(fbf_h2), .h3(fbf_h3),
        .out_valid(fbf_out_valid), .f1(fbf_f1), .f2(fbf_f2), .f3(fbf_f3), .dbg()
    );
endmodule
