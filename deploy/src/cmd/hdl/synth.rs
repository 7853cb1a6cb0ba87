//! `tactile hdl synth`: Yosys synthesizes each block for Virtex-6 (the paper's family,
//! `synth_xilinx -family xc6v`) and reports its resources, its pipeline's latency and
//! its logic depth. Yosys has no Virtex-6 timing model, so the depth stands in for a
//! clock rate: the most logic cells (LUTs, CARRY4s, MUXF7/8s) on one path between
//! registers (`ltp` over every cell but the flip-flops, SRLs and DSP48s, which end a
//! path).

use super::sim::{chosen, tool, Work};
use super::Bench as _;
use super::{latency, model, write_rtl, Block, Pipeline, PipelineArg, MODULES};
use crate::cmd::datapath::DatapathArgs;
use clap::Args;
use std::path::PathBuf;
use std::process::Command;
use tactile_launch::error::Error;

/// Arguments of `tactile hdl synth`.
#[derive(Debug, Args)]
pub struct SynthArgs {
    /// Blocks to synthesize (default: the TFB's three functions).
    #[arg(long, value_parser = super::block_parser(), value_delimiter = ',')]
    pub function: Vec<Block>,
    /// Also synthesize the paper's five modules as one design (FK-HMD, KFF-HMD,
    /// FK-HSD, IK-HSD, FBF-HSD), as its table's total.
    #[arg(long)]
    pub together: bool,
    /// Which stage registers the modules keep (the bits are the same in each).
    #[arg(long, value_enum, default_value = "sample")]
    pub pipeline: PipelineArg,
    /// Keep the work folder (RTL, scripts, Yosys logs) here.
    #[arg(long)]
    pub keep: Option<PathBuf>,
    /// Fixed-point format and the arm's geometry.
    #[command(flatten)]
    pub datapath: DatapathArgs,
}

/// Resources of one synthesized block, from Yosys's `stat`.
#[derive(Debug, Default, Clone, Copy, PartialEq, Eq)]
pub struct Resources {
    /// Flip-flops (FDRE, FDSE, FDCE, FDPE).
    pub registers: u64,
    /// LUTs used as logic (LUT1..LUT6).
    pub luts: u64,
    /// LUTs used as shift registers (SRL16E, SRLC32E): delay lines.
    pub srls: u64,
    /// DSP48E1 slices.
    pub dsps: u64,
    /// CARRY4 chains.
    pub carry: u64,
}

/// Parses the cell counts of Yosys's `stat` (the flattened top's list).
pub fn parse_stat(text: &str) -> Resources {
    let mut r = Resources::default();
    for line in text.lines() {
        let mut it = line.split_whitespace();
        let (Some(cell), Some(n), None) = (it.next(), it.next(), it.next()) else {
            continue;
        };
        let Ok(n) = n.parse::<u64>() else { continue };
        match cell {
            "FDRE" | "FDSE" | "FDCE" | "FDPE" => r.registers += n,
            c if c.starts_with("LUT") && c.len() == 4 => r.luts += n,
            "SRL16E" | "SRLC32E" => r.srls += n,
            "DSP48E1" => r.dsps += n,
            "CARRY4" => r.carry += n,
            _ => {}
        }
    }
    r
}

/// The cells on the longest path from `ltp`'s line "Longest topological path in X
/// (length=N):".
pub fn parse_ltp(text: &str) -> Option<u64> {
    let at = text.find("(length=")? + "(length=".len();
    text[at..].split(')').next()?.parse().ok()
}

/// The synthesis top of a block and the `chparam` it needs (the subtractor is the
/// adder with SUB = 1).
fn top(f: Block) -> (String, &'static str) {
    match f.family() {
        super::Family::Unit(_) if f == Block::Sub => {
            ("f32_add".into(), "chparam -set SUB 1 f32_add; ")
        }
        super::Family::Unit(_) => (format!("f32_{}", f.name()), ""),
        _ => (format!("top_{}", f.name()), ""),
    }
}

/// Synthesizes one top: its resources and its depth.
fn synthesize(
    work: &Work,
    name: &str,
    top: &str,
    chparam: &str,
) -> Result<(Resources, Option<u64>), Error> {
    let stat = work.dir.join(format!("{name}.stat"));
    let ltp = work.dir.join(format!("{name}.ltp"));
    let script = format!(
        "read_verilog -I . {modules} tfb_top.v kin_top.v; {chparam}\
         synth_xilinx -family xc6v -flatten -top {top}; tee -q -o {stat} stat; \
         tee -q -o {ltp} ltp t:FD* t:SRL* t:DSP48E1 %u %u %n",
        modules = MODULES.join(" "),
        stat = stat.display(),
        ltp = ltp.display()
    );
    let mut y = Command::new("yosys");
    y.current_dir(&work.dir).args(["-q", "-p", &script]);
    tool(&mut y, "yosys", "yosys")?;
    let read = |p: &PathBuf| {
        std::fs::read_to_string(p).map_err(Error::io(format!("reading {}", p.display())))
    };
    Ok((parse_stat(&read(&stat)?), parse_ltp(&read(&ltp)?)))
}

/// `tactile hdl synth`.
pub fn synth_main(args: &SynthArgs) -> Result<(), Error> {
    let cfg = args.datapath.cordic()?;
    let (_, k) = model(cfg)?;
    let work = Work::new(args.keep.as_deref())?;
    let pipeline = Pipeline::from(args.pipeline);
    write_rtl(&work.dir, &k, &args.datapath.geometry()?, pipeline)?;
    tactile_launch::outln!(
        "| block | format | rounding | registers | LUTs | SRLs | DSP48E1 | CARRY4 | latency (clocks) | depth (cells) |"
    );
    tactile_launch::outln!("|---|---|---|---:|---:|---:|---:|---:|---:|---:|");
    let format = format!("[s{}.{}] {} it.", cfg.word, cfg.frac, cfg.iterations);
    let rounding = format!("{:?}", cfg.rounding).to_lowercase();
    let row = |name: &str, r: Resources, lat: String, depth: Option<u64>| {
        let depth = depth.map_or("?".into(), |d| d.to_string());
        tactile_launch::outln!(
            "| {name} | {format} | {rounding} | {} | {} | {} | {} | {} | {lat} | {depth} |",
            r.registers,
            r.luts,
            r.srls,
            r.dsps,
            r.carry
        );
    };
    let blocks = chosen(
        &args.function,
        if args.together { &[] } else { &Block::TFB },
    );
    for f in blocks {
        let (t, chparam) = top(f);
        let (r, depth) = synthesize(&work, f.name(), &t, chparam)?;
        row(f.name(), r, latency(f, &cfg, pipeline).to_string(), depth);
    }
    if args.together {
        let (r, depth) = synthesize(&work, "all", "top_all", "")?;
        row("all five", r, "-".into(), depth);
    }
    Ok(())
}
