//! The RTL in the loop (`arithmetic = "rtl"`): the clocks each of the paper's modules
//! took per sample, from the nodes' counters, as time at a stated clock beside the
//! software's stage times. Yosys has no Virtex-6 timing model, so the clock is stated,
//! not measured: [`CLOCK_MHZ`].

use crate::analysis::Percentiles;
use serde::Serialize;
use std::collections::BTreeMap;
use tactile_math::hardware::{Clocks, Module};

/// The clock the hardware's times are stated at, MHz: a rate an f32 pipeline of this
/// depth (docs/09's synthesis table) reaches on a Virtex-6 by the vendor's figures; an
/// assumption to read the clocks by, not a timing result.
pub const CLOCK_MHZ: f64 = 100.0;

/// One module's clocks over the run.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct ModuleClocks {
    /// Samples put through it.
    pub calls: u64,
    /// The fewest and the most clocks a sample took (a pipeline: both its latency).
    pub min: u32,
    /// The most.
    pub max: u32,
    /// Mean clocks a sample, and that time at [`CLOCK_MHZ`], ns.
    pub mean: f64,
    /// `mean` at the stated clock, ns.
    pub ns: f64,
}

/// The hardware's part of a run's summary.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct HardwareSummary {
    /// The stated clock, MHz.
    pub clock_mhz: f64,
    /// Per module, the paper's names (FK-HMD, KFF-HMD: the master's; IK-HSD, FK-HSD,
    /// FBF-HSD: the slave's).
    pub modules: BTreeMap<&'static str, ModuleClocks>,
    /// Samples the hardware flagged as not computed (an angle beyond the TFB's range).
    pub faults: u64,
}

fn module(c: &Clocks, m: Module) -> Option<ModuleClocks> {
    let i = Module::ALL.iter().position(|&x| x == m)?;
    let calls = c.calls[i];
    (calls > 0).then(|| {
        let mean = c.total[i] as f64 / calls as f64;
        ModuleClocks {
            calls,
            min: c.min[i],
            max: c.max[i],
            mean,
            ns: mean * 1e3 / CLOCK_MHZ,
        }
    })
}

/// The summary's hardware part from the master's and the slave's clocks; `None` when
/// neither ran the RTL.
pub fn summary(master: &Clocks, slave: &Clocks) -> Option<HardwareSummary> {
    if master.is_empty() && slave.is_empty() {
        return None;
    }
    let names = [
        ("FK-HMD", master, Module::Fk),
        ("KFF-HMD", master, Module::Kff),
        ("IK-HSD", slave, Module::Ik),
        ("FK-HSD", slave, Module::Fk),
        ("FBF-HSD", slave, Module::Fbf),
    ];
    Some(HardwareSummary {
        clock_mhz: CLOCK_MHZ,
        modules: names
            .iter()
            .filter_map(|(name, c, m)| Some((*name, module(c, *m)?)))
            .collect(),
        faults: master.faults + slave.faults,
    })
}

/// The report's lines: each module's clocks and time, then the software's stages that
/// hold the same work (their medians), for comparison.
pub fn lines(h: &HardwareSummary, stages: &BTreeMap<String, Percentiles>) -> Vec<String> {
    let mut out = vec![format!(
        "hardware (the RTL, clock by clock in Verilator; times at a stated {} MHz):",
        h.clock_mhz
    )];
    for (name, m) in &h.modules {
        let clocks = if m.min == m.max {
            format!("{} clocks", m.min)
        } else {
            format!("{}..{} clocks", m.min, m.max)
        };
        out.push(format!(
            "  {name}: {clocks} a call ({:.0} ns), {} calls",
            m.ns, m.calls
        ));
    }
    let hmd: f64 = ["FK-HMD", "KFF-HMD"]
        .iter()
        .filter_map(|n| h.modules.get(n))
        .map(|m| m.ns)
        .sum();
    let hsd: f64 = ["IK-HSD", "FK-HSD", "FBF-HSD"]
        .iter()
        .filter_map(|n| h.modules.get(n))
        .map(|m| m.ns)
        .sum();
    let p50 = |s: &str| {
        stages.get(s).map_or("n/a".to_string(), |p| {
            format!("{:.1} us", p.p50 as f64 / 1e3)
        })
    };
    out.push(format!(
        "  the master's modules {:.2} us a sample in hardware; its software stages (p50, with the rest of its work): tick to send {}, backward compute {}",
        hmd / 1e3,
        p50("master_tick_to_send"),
        p50("master_compute_bwd")
    ));
    out.push(format!(
        "  the slave's modules {:.2} us a sample in hardware; its software stage (p50, with the dynamics): compute {}",
        hsd / 1e3,
        p50("slave_compute")
    ));
    if h.faults > 0 {
        out.push(format!(
            "  {} samples the hardware could not compute (angle beyond the TFB's range): NaN",
            h.faults
        ));
    }
    out
}
