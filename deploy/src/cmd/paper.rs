//! `tactile paper`: the paper's MSE table from our own kernels.

use super::datapath::DatapathArgs;
use clap::Args;
use serde::Serialize;
use std::io::Write;
use tactile_launch::error::Error;
use tactile_math::cordic::{CordicConfig, Rounding};
use tactile_math::validation::{self, MseRow};

/// Arguments of `tactile paper`.
#[derive(Debug, Args)]
pub struct PaperArgs {
    /// Print JSON instead of a table.
    #[arg(long)]
    pub json: bool,
    /// Datapath format and device.
    #[command(flatten)]
    pub datapath: DatapathArgs,
}

#[derive(Debug, Serialize)]
struct Report<'a> {
    samples: usize,
    t_s: f64,
    device: &'a str,
    cordic: CordicConfig,
    rows: &'a [MseRow],
    all_within_paper: bool,
}

/// Runs the validation trajectory and prints the table (or JSON) to `out`.
pub fn run(args: &PaperArgs, out: &mut impl Write) -> Result<(), Error> {
    let geometry = args.datapath.geometry()?;
    let cordic = args.datapath.cordic()?;
    let rows = validation::mse_table(&geometry, cordic)
        .map_err(|e| Error::BadInput(format!("bad fixed-point format: {e}")))?;
    let all_within = rows.iter().all(|r| r.mse <= r.paper_mse);
    let text = if args.json {
        let report = Report {
            samples: validation::SAMPLES,
            t_s: validation::T_S,
            device: &args.datapath.device,
            cordic,
            rows: &rows,
            all_within_paper: all_within,
        };
        let mut s = serde_json::to_string_pretty(&report)
            .map_err(|e| Error::Failed(format!("encoding JSON: {e}")))?;
        s.push('\n');
        s
    } else {
        render_table(&rows, &cordic, &args.datapath.device, all_within)
    };
    out.write_all(text.as_bytes())
        .map_err(Error::io("writing stdout"))
}

fn render_table(rows: &[MseRow], c: &CordicConfig, device: &str, all_within: bool) -> String {
    use std::fmt::Write as _;
    let rounding = match c.rounding {
        Rounding::Truncate => "truncate",
        Rounding::Nearest => "nearest",
    };
    let mut s = String::new();
    let _ = writeln!(
        s,
        "Paper validation run: {} samples at t_s = {} s, device {device}",
        validation::SAMPLES,
        validation::T_S
    );
    let _ = writeln!(
        s,
        "hybrid = f32 + CORDIC [s{}.{}], {} iterations, {rounding} rounding; MSE against the f32 software model\n",
        c.word, c.frac, c.iterations
    );
    let _ = writeln!(
        s,
        "{:<8} {:<11} {:>12} {:>12} {:>9} {:>14}",
        "module", "variable", "our MSE", "paper MSE", "ours/pap", "f32-vs-f64 MSE"
    );
    for r in rows {
        let ratio = if r.paper_mse > 0.0 {
            r.mse / r.paper_mse
        } else {
            f64::NAN
        };
        let _ = writeln!(
            s,
            "{:<8} {:<11} {:>12.3e} {:>12.3e} {:>9.2e} {:>14.3e}",
            r.module, r.variable, r.mse, r.paper_mse, ratio, r.f32_vs_f64_mse
        );
    }
    let _ = writeln!(
        s,
        "\n{}",
        if all_within {
            "every module and variable is at or below the paper's MSE"
        } else {
            "some rows exceed the paper's MSE"
        }
    );
    s
}
