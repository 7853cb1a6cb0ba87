// The C ABI between Rust (src/sim.rs) and Verilator's models of the four modules.
// Each call puts one sample on a module's ports with in_valid, clocks it until
// out_valid (the pipeline's latency: one sample in flight, as the loop computes one
// sample at a time), reads the outputs and returns the clocks it took (0 if out_valid
// never came within LIMIT clocks: a broken pipeline, reported by the caller).
#include <cstdint>
#include "verilated.h"
#include "Vkin_fk.h"
#include "Vkin_kff.h"
#include "Vkin_fbf.h"
#include "Vkin_ik.h"

namespace {
const uint32_t LIMIT = 100000;

struct Chip {
    VerilatedContext c_fk, c_kff, c_fbf, c_ik;
    Vkin_fk fk{&c_fk, "fk"};
    Vkin_kff kff{&c_kff, "kff"};
    Vkin_fbf fbf{&c_fbf, "fbf"};
    Vkin_ik ik{&c_ik, "ik"};
};

// Clocks `m` from the sample on its inputs to its out_valid.
template <class M> uint32_t clock_through(M& m) {
    m.in_valid = 1;
    uint32_t clocks = 0;
    do {
        m.clk = 1;
        m.eval();
        m.clk = 0;
        m.in_valid = 0;
        m.eval();
        clocks++;
    } while (!m.out_valid && clocks < LIMIT);
    return m.out_valid ? clocks : 0;
}

template <class M> void settle(M& m) {
    m.clk = 0;
    m.in_valid = 0;
    m.eval();
}
}  // namespace

extern "C" {

void* tactile_rtl_new() {
    Chip* chip = new Chip();
    settle(chip->fk);
    settle(chip->kff);
    settle(chip->fbf);
    settle(chip->ik);
    return chip;
}

void tactile_rtl_free(void* p) {
    Chip* chip = static_cast<Chip*>(p);
    chip->fk.final();
    chip->kff.final();
    chip->fbf.final();
    chip->ik.final();
    delete chip;
}

// in: t1 t2 t3; out: x y z err.
uint32_t tactile_rtl_fk(void* p, const uint32_t* in, uint32_t* out) {
    Vkin_fk& m = static_cast<Chip*>(p)->fk;
    m.t1 = in[0];
    m.t2 = in[1];
    m.t3 = in[2];
    uint32_t clocks = clock_through(m);
    out[0] = m.x;
    out[1] = m.y;
    out[2] = m.z;
    out[3] = m.err;
    return clocks;
}

// in: t1 t2 t3 f1 f2 f3; out: tau1 tau2 tau3 err, then J by rows (j11 .. j33).
uint32_t tactile_rtl_kff(void* p, const uint32_t* in, uint32_t* out) {
    Vkin_kff& m = static_cast<Chip*>(p)->kff;
    m.t1 = in[0];
    m.t2 = in[1];
    m.t3 = in[2];
    m.f1 = in[3];
    m.f2 = in[4];
    m.f3 = in[5];
    uint32_t clocks = clock_through(m);
    out[0] = m.tau1;
    out[1] = m.tau2;
    out[2] = m.tau3;
    out[3] = m.err;
    // dbg = {s1,c1,s2,c2,s3,c3,j11..j33}: word 0 (bits 31:0) is j33.
    for (int k = 0; k < 9; k++) out[4 + k] = m.dbg[8 - k];
    return clocks;
}

// in: o1 o2 o3 e1 e2 e3 h1 h2 h3; out: f1 f2 f3.
uint32_t tactile_rtl_fbf(void* p, const uint32_t* in, uint32_t* out) {
    Vkin_fbf& m = static_cast<Chip*>(p)->fbf;
    m.o1 = in[0];
    m.o2 = in[1];
    m.o3 = in[2];
    m.e1 = in[3];
    m.e2 = in[4];
    m.e3 = in[5];
    m.h1 = in[6];
    m.h2 = in[7];
    m.h3 = in[8];
    uint32_t clocks = clock_through(m);
    out[0] = m.f1;
    out[1] = m.f2;
    out[2] = m.f3;
    return clocks;
}

// in: x y z; out: t1 t2 t3 status.
uint32_t tactile_rtl_ik(void* p, const uint32_t* in, uint32_t* out) {
    Vkin_ik& m = static_cast<Chip*>(p)->ik;
    m.x = in[0];
    m.y = in[1];
    m.z = in[2];
    uint32_t clocks = clock_through(m);
    out[0] = m.t1;
    out[1] = m.t2;
    out[2] = m.t3;
    out[3] = m.status;
    return clocks;
}

}  // extern "C"
