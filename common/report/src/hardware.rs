//! The RTL in the loop (`arithmetic = "rtl"`): the clocks each of the paper's modules
//! took per sample, from the nodes' counters, and what those clocks take on a real
//! part: the clock each module reached when placed and routed ([`PLACED`], measured by
//! `tactile hdl timing`, docs/09), beside the software's stage times.

use crate::analysis::Percentiles;
use serde::Serialize;
use std::collections::BTreeMap;
use tactile_math::cordic::CordicConfig;
use tactile_math::geometry::Geometry;
use tactile_math::hardware::{Clocks, Module};
use tactile_rtl::text::{Block, Pipeline};

/// The part the clocks below were measured on.
pub const PART: &str = "Lattice ECP5 LFE5U-85F, speed 6 (Yosys synth_ecp5, nextpnr-ecp5)";

/// The format and geometry [`PLACED`] was measured in: a run in another gets clocks
/// and no time.
pub const PLACED_FOR: (CordicConfig, Geometry) = (CordicConfig::S16_13, Geometry::PAPER);

/// Each module's clock, MHz, as placed and routed on [`PART`] in [`PLACED_FOR`] (the
/// paper's [s16.13] nearest and geometry), seed 1: `tactile hdl timing --pipeline P --function M`
/// (docs/09, "Timing from a real place and route"). A module not listed was not
/// placed in that pipeline, and its time is not claimed.
pub const PLACED: [(Pipeline, Block, f64); 9] = [
    (Pipeline::Module, Block::Fbf, 10.46),
    (Pipeline::Module, Block::Fk, 2.89),
    (Pipeline::Module, Block::Kff, 2.21),
    (Pipeline::Unit, Block::Fbf, 19.33),
    (Pipeline::Unit, Block::Fk, 6.45),
    (Pipeline::Unit, Block::Ik, 5.33),
    (Pipeline::Sample, Block::Fbf, 37.0),
    (Pipeline::Sample, Block::Fk, 34.9),
    (Pipeline::Sample, Block::Kff, 36.9),
];

/// One module's clocks over the run.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct ModuleClocks {
    /// Samples put through it.
    pub calls: u64,
    /// The fewest and the most clocks a sample took (a pipeline: both its latency).
    pub min: u32,
    /// The most.
    pub max: u32,
    /// Mean clocks a sample.
    pub mean: f64,
    /// The clock it reached on [`PART`] in this pipeline, MHz, if it was placed.
    pub fmax_mhz: Option<f64>,
    /// `mean` at that clock, ns.
    pub ns: Option<f64>,
}

/// The hardware's part of a run's summary.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct HardwareSummary {
    /// The pipeline configuration the nodes simulated (`sample`, `unit`, `module`),
    /// known by the clocks a sample took; `None` if they match none.
    pub pipeline: Option<&'static str>,
    /// Where the clock rates come from.
    pub part: &'static str,
    /// Whether the run's format and geometry are those the modules were placed in
    /// ([`PLACED_FOR`]); if not, no module has a time.
    pub placed_for_this_datapath: bool,
    /// Per module, the paper's names (FK-HMD, KFF-HMD: the master's; IK-HSD, FK-HSD,
    /// FBF-HSD: the slave's).
    pub modules: BTreeMap<&'static str, ModuleClocks>,
    /// Samples the hardware flagged as not computed (an angle beyond the TFB's range).
    pub faults: u64,
}

fn block(m: Module) -> Block {
    match m {
        Module::Fk => Block::Fk,
        Module::Kff => Block::Kff,
        Module::Fbf => Block::Fbf,
        Module::Ik => Block::Ik,
    }
}

/// The pipeline whose latencies every module that ran took, with `iterations`.
fn pipeline_of(clocks: &[&Clocks], iterations: u32) -> Option<Pipeline> {
    Pipeline::ALL.into_iter().find(|p| {
        clocks.iter().all(|c| {
            Module::ALL.iter().enumerate().all(|(i, &m)| {
                let want = p.latency(block(m), iterations);
                c.calls[i] == 0 || (c.min[i] == want && c.max[i] == want)
            })
        })
    })
}

fn module(c: &Clocks, m: Module, placed: Option<Pipeline>) -> Option<ModuleClocks> {
    let i = Module::ALL.iter().position(|&x| x == m)?;
    let calls = c.calls[i];
    let fmax = PLACED
        .iter()
        .find(|(p, b, _)| Some(*p) == placed && *b == block(m))
        .map(|(_, _, mhz)| *mhz);
    (calls > 0).then(|| {
        let mean = c.total[i] as f64 / calls as f64;
        ModuleClocks {
            calls,
            min: c.min[i],
            max: c.max[i],
            mean,
            fmax_mhz: fmax,
            ns: fmax.map(|f| mean * 1e3 / f),
        }
    })
}

/// The summary's hardware part from the master's and the slave's clocks, for the run's
/// format and geometry (`None` if unknown); `None` when neither ran the RTL.
pub fn summary(
    master: &Clocks,
    slave: &Clocks,
    datapath: Option<(CordicConfig, Geometry)>,
) -> Option<HardwareSummary> {
    if master.is_empty() && slave.is_empty() {
        return None;
    }
    let iterations = datapath.map_or(0, |(c, _)| c.iterations);
    let pipeline = pipeline_of(&[master, slave], iterations);
    let placed_for_this_datapath = datapath == Some(PLACED_FOR);
    let placed = pipeline.filter(|_| placed_for_this_datapath);
    let names = [
        ("FK-HMD", master, Module::Fk),
        ("KFF-HMD", master, Module::Kff),
        ("IK-HSD", slave, Module::Ik),
        ("FK-HSD", slave, Module::Fk),
        ("FBF-HSD", slave, Module::Fbf),
    ];
    Some(HardwareSummary {
        pipeline: pipeline.map(Pipeline::name),
        part: PART,
        placed_for_this_datapath,
        modules: names
            .iter()
            .filter_map(|(name, c, m)| Some((*name, module(c, *m, placed)?)))
            .collect(),
        faults: master.faults + slave.faults,
    })
}

/// A side's modules in hardware, us a sample: their sum, or why there is none.
fn side(h: &HardwareSummary, names: &[&str]) -> String {
    let ran: Vec<&ModuleClocks> = names.iter().filter_map(|n| h.modules.get(n)).collect();
    match ran.iter().map(|m| m.ns).sum::<Option<f64>>() {
        Some(ns) if !ran.is_empty() => format!("{:.2} us a sample in hardware", ns / 1e3),
        _ => "not all placed, so no time in hardware".to_string(),
    }
}

/// The report's lines: each module's clocks and time, then the software's stages that
/// hold the same work (their medians), for comparison.
pub fn lines(h: &HardwareSummary, stages: &BTreeMap<String, Percentiles>) -> Vec<String> {
    let mut out = vec![format!(
        "hardware (the RTL, clock by clock in Verilator, pipeline {}; times at the clocks placed and routed on a {PART}, docs/09):",
        h.pipeline.unwrap_or("unknown")
    )];
    for (name, m) in &h.modules {
        let clocks = if m.min == m.max {
            format!("{} clock{}", m.min, if m.min == 1 { "" } else { "s" })
        } else {
            format!("{}..{} clocks", m.min, m.max)
        };
        let time = match (m.ns, m.fmax_mhz) {
            (Some(ns), Some(f)) => format!("{ns:.0} ns at {f} MHz"),
            _ if !h.placed_for_this_datapath => {
                "placed and routed only in the paper's [s16.13] and geometry".to_string()
            }
            _ => "not placed and routed in this pipeline".to_string(),
        };
        out.push(format!(
            "  {name}: {clocks} a call ({time}), {} calls",
            m.calls
        ));
    }
    let p50 = |s: &str| {
        stages.get(s).map_or("n/a".to_string(), |p| {
            format!("{:.1} us", p.p50 as f64 / 1e3)
        })
    };
    out.push(format!(
        "  the master's modules {}; its software stages (p50, with the rest of its work): tick to send {}, backward compute {}",
        side(h, &["FK-HMD", "KFF-HMD"]),
        p50("master_tick_to_send"),
        p50("master_compute_bwd")
    ));
    out.push(format!(
        "  the slave's modules {}; its software stage (p50, with the dynamics): compute {}",
        side(h, &["IK-HSD", "FK-HSD", "FBF-HSD"]),
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

#[cfg(test)]
mod tests {
    use super::*;

    /// Clocks of `calls` samples through FK, KFF, FBF, IK, each taking `lat`.
    fn clocks(calls: [u64; 4], lat: [u32; 4]) -> Clocks {
        Clocks {
            calls,
            total: [0, 1, 2, 3].map(|i| calls[i] * u64::from(lat[i])),
            min: lat,
            max: lat,
            faults: 0,
        }
    }

    #[test]
    fn the_pipeline_is_known_by_its_clocks_and_only_placed_modules_get_a_time() {
        let master = clocks([10, 20, 0, 0], [35, 43, 0, 0]);
        let slave = clocks([10, 0, 4, 10], [35, 0, 8, 175]);
        let h = summary(&master, &slave, Some(PLACED_FOR)).expect("hardware ran");
        assert_eq!(h.pipeline, Some("sample"));
        let fk = h.modules["FK-HMD"];
        assert_eq!(fk.fmax_mhz, Some(34.9));
        assert!((fk.ns.expect("placed") - 35_000.0 / 34.9).abs() < 1e-9);
        assert_eq!(h.modules["IK-HSD"].ns, None);
        let text = lines(&h, &BTreeMap::new()).join("\n");
        assert!(
            text.contains("IK-HSD: 175 clocks a call (not placed and routed"),
            "{text}"
        );
        assert!(
            text.contains("the slave's modules not all placed"),
            "{text}"
        );
        let master_us = (35.0 / 34.9 + 43.0 / 36.9) / 1.0;
        assert!(
            text.contains(&format!("the master's modules {master_us:.2} us")),
            "{text}"
        );
    }

    #[test]
    fn clocks_no_pipeline_gives_are_said_to_be_unknown() {
        let one = clocks([5, 5, 5, 5], [1, 1, 1, 1]);
        let h = summary(&one, &one, Some(PLACED_FOR)).expect("hardware ran");
        assert_eq!(h.pipeline, Some("module"));
        assert_eq!(h.modules["FK-HMD"].fmax_mhz, Some(2.89));
        assert_eq!(h.modules["KFF-HMD"].fmax_mhz, Some(2.21));
        // Another format: the same clocks, and no time (the modules were placed in
        // the paper's only).
        let wide = CordicConfig::new(24, 21, None, tactile_math::cordic::Rounding::Nearest)
            .expect("a format");
        let h = summary(&one, &one, Some((wide, Geometry::PAPER))).expect("hardware ran");
        assert_eq!(
            (h.pipeline, h.placed_for_this_datapath),
            (Some("module"), false)
        );
        assert!(h.modules.values().all(|m| m.ns.is_none()));
        let text = lines(&h, &BTreeMap::new()).join("\n");
        assert!(text.contains("only in the paper's [s16.13]"), "{text}");
        // FK at 35 clocks beside IK at one: no configuration does that.
        let odd = clocks([5, 0, 0, 5], [35, 0, 0, 1]);
        let h = summary(&odd, &Clocks::default(), Some(PLACED_FOR)).expect("hardware ran");
        assert_eq!(h.pipeline, None);
        assert!(h.modules.values().all(|m| m.ns.is_none()));
        assert!(summary(&Clocks::default(), &Clocks::default(), Some(PLACED_FOR)).is_none());
    }
}
