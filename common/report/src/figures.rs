//! A run's histogram files and plots: `round_trip.hgrm`, `overhead.hgrm`,
//! `latency.svg` (the overhead's histogram), `percentiles.svg` and the time series.
//!
//! They say what the summary says. In lockstep the system overhead is not measured
//! (`overhead_ns` null, "n/a" in the text: a sample's wall-clock time holds the others
//! computed meanwhile), so no `overhead.hgrm` and no `latency.svg` are written (an
//! older one is removed) and `percentiles.svg` draws the round trip alone: a histogram
//! of zeros there read as an overhead of nothing.

use crate::analysis::Analysis;
use crate::out::{remove_if_there, write_file};
use crate::plots::{self, Series};
use crate::Error;
use std::path::Path;

/// Writes the run's histograms and plots into `out`; `lockstep`: the overhead is not
/// measured.
pub fn write(
    out: &Path,
    analysis: &Analysis,
    series: &Series,
    lockstep: bool,
) -> Result<(), Error> {
    let round_trip = analysis.round_trip.hgrm();
    write_file(&out.join("round_trip.hgrm"), &round_trip)?;
    let plot = |name: &str, res: plots::PlotResult| {
        res.map_err(|source| Error::Plot {
            what: format!("plotting {name}"),
            source,
        })
    };
    let mut lines = vec![("round trip".to_string(), plots::read_hgrm(&round_trip))];
    if lockstep {
        remove_if_there(&out.join("overhead.hgrm"))?;
        remove_if_there(&out.join("latency.svg"))?;
    } else {
        let overhead = analysis.overhead.hgrm();
        write_file(&out.join("overhead.hgrm"), &overhead)?;
        plot(
            "latency",
            plots::whole_svg(&out.join("latency.svg"), |p| {
                plots::overhead_histogram(&analysis.overhead, p)
            }),
        )?;
        lines.push(("system overhead".into(), plots::read_hgrm(&overhead)));
    }
    plot(
        "percentiles",
        plots::whole_svg(&out.join("percentiles.svg"), |p| {
            plots::percentile_plot(p, "Latency by percentile", &lines)
        }),
    )?;
    plot("positions and forces", series.write(out))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::trace::TraceRow;

    /// An in-process run's answers: round trips of exactly 50 ms, overheads of 0.
    fn analysis() -> Analysis {
        let mut a = Analysis::new(false, Default::default());
        for n in 0..100u64 {
            a.add(&TraceRow {
                n,
                received: true,
                round_trip_ns: 50_000_000,
                overhead_ns: 0,
                contact_object: -1,
                ..TraceRow::default()
            });
        }
        a
    }

    /// In lockstep no overhead file or histogram (an older one removed), and the
    /// percentile plot has the round trip alone, at exactly 50 ms; in real time both.
    #[test]
    fn lockstep_draws_no_overhead_it_did_not_measure() {
        let dir = tempfile::tempdir().expect("tmp");
        let out = dir.path();
        std::fs::write(out.join("latency.svg"), "<svg/>").expect("old plot");
        write(out, &analysis(), &Series::default(), true).expect("figures");
        assert!(!out.join("latency.svg").exists() && !out.join("overhead.hgrm").exists());
        let svg = std::fs::read_to_string(out.join("percentiles.svg")).expect("plot");
        let texts = crate::plots::looks::svg::texts(&svg);
        assert!(texts.iter().any(|t| t == "round trip"), "{texts:?}");
        assert!(!texts.iter().any(|t| t == "system overhead"), "{texts:?}");
        let hgrm = std::fs::read_to_string(out.join("round_trip.hgrm")).expect("hgrm");
        assert_eq!(plots::read_hgrm(&hgrm).pop(), Some((1.0, 50_000.0)));
        write(out, &analysis(), &Series::default(), false).expect("figures");
        assert!(out.join("latency.svg").exists() && out.join("overhead.hgrm").exists());
        let svg = std::fs::read_to_string(out.join("percentiles.svg")).expect("plot");
        assert!(svg.contains("system overhead"));
    }
}
