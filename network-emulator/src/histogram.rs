//! Loading the delay histograms a scenario draws its delays from (the edge: a file is
//! read here, or a shipped histogram taken, checked, put in samples at the scenario's
//! rate and handed to the pure channel).

use std::path::{Path, PathBuf};
use tactile_netem::{DelayHistogram, HistogramDelay, HistogramError};
use tactile_scenario::{
    shipped_histogram, ChannelConfig, HistogramConfig, Scenario, MAX_DELAY_SAMPLES,
};

/// Largest histogram file accepted, bytes: a million bins of 16 characters.
pub const MAX_HISTOGRAM_BYTES: u64 = 16 << 20;

/// A delay histogram the scenario names that cannot be used; each message names the
/// field and the file (and the file's line).
#[derive(Debug, thiserror::Error)]
pub enum LoadError {
    /// The file cannot be read.
    #[error("{field}.path: {source}")]
    Read {
        /// The scenario's field (`network.forward.delay_histogram`).
        field: &'static str,
        /// Why.
        source: tactile_runtime::files::FileError,
    },
    /// The file is read, but it is no histogram (or one beyond the longest delay).
    #[error("{field}: {}: {source}", path.display())]
    Parse {
        /// The scenario's field.
        field: &'static str,
        /// The file (a shipped one's under `deploy/networks/`).
        path: PathBuf,
        /// What is wrong in it.
        source: HistogramError,
    },
}

/// The forward and backward delay histograms of `scenario` in samples, paths relative
/// to `base_dir`; the error names the field and the file.
pub fn load(
    scenario: &Scenario,
    base_dir: &Path,
) -> Result<[Option<HistogramDelay>; 2], LoadError> {
    let one = |field: &'static str, c: &ChannelConfig| {
        c.delay_histogram
            .as_ref()
            .map(|h| read(field, h, scenario.rate_hz, base_dir))
            .transpose()
    };
    Ok([
        one("network.forward.delay_histogram", &scenario.network.forward)?,
        one(
            "network.backward.delay_histogram",
            &scenario.network.backward,
        )?,
    ])
}

fn read(
    field: &'static str,
    cfg: &HistogramConfig,
    rate_hz: f64,
    base_dir: &Path,
) -> Result<HistogramDelay, LoadError> {
    // The scenario's checks leave a path or a shipped name.
    let (path, parsed) = match (&cfg.path, cfg.name.as_deref().and_then(shipped_histogram)) {
        (Some(p), _) => {
            let path = base_dir.join(p);
            let text =
                tactile_runtime::files::read_text(&path, "delay histogram", MAX_HISTOGRAM_BYTES)
                    .map_err(|source| LoadError::Read { field, source })?;
            let parsed = DelayHistogram::parse(&text, cfg.format.unwrap_or_default());
            (path, parsed)
        }
        (None, Some(s)) => (
            Path::new("deploy/networks").join(s.file),
            DelayHistogram::parse(s.text, s.format),
        ),
        (None, None) => (PathBuf::new(), Err(HistogramError::NoBin)),
    };
    let samples = parsed.and_then(|h| h.in_samples(rate_hz, MAX_DELAY_SAMPLES));
    let histogram = samples.map_err(|source| LoadError::Parse {
        field,
        path,
        source,
    })?;
    Ok(HistogramDelay::new(histogram, cfg.correlation))
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::error::Error as _;

    fn with_histogram(spec: &str) -> Scenario {
        let text = format!("rate_hz = 1000.0\n[network.backward.delay_histogram]\n{spec}\n");
        Scenario::from_toml_str(&text).expect("a scenario with a histogram")
    }

    /// A missing file and a bad one each keep their cause under the field's name;
    /// every shipped histogram loads, and one beyond the longest delay is refused.
    #[test]
    fn a_histogram_error_keeps_its_cause_and_the_shipped_ones_load() {
        let dir = tempfile::tempdir().expect("tmp");
        let refused = |spec: &str, file: &str, text: &str| {
            std::fs::write(dir.path().join(file), text).expect("write");
            load(&with_histogram(spec), dir.path()).expect_err(spec)
        };
        let missing = load(&with_histogram("path = \"gone.csv\""), dir.path()).expect_err("gone");
        let bad = refused(
            "path = \"bad.csv\"",
            "bad.csv",
            "delay_ms,count\n1,-2\n2,0\n",
        );
        let long = refused(
            "path = \"long.csv\"",
            "long.csv",
            "delay_ms,count\n1,1\n200000,0\n",
        );
        for (e, want) in [
            (
                &missing,
                "network.backward.delay_histogram.path: cannot read delay histogram",
            ),
            (&bad, "network.backward.delay_histogram: "),
            (&long, "network.backward.delay_histogram: "),
        ] {
            assert!(e.to_string().starts_with(want), "{e}");
        }
        assert!(bad
            .to_string()
            .ends_with("bad.csv: line 2: count -2 is negative"));
        assert!(long.to_string().ends_with(
            "long.csv: line 3: delay_ms 200000 ms is 200000 samples at 1000 Hz, beyond 100000"
        ));
        let cause = missing.source().expect("the file's error");
        assert!(cause.source().is_some_and(|c| c.is::<std::io::Error>()));
        assert_eq!(
            bad.source()
                .and_then(|c| c.downcast_ref::<HistogramError>()),
            Some(&HistogramError::NegativeCount {
                line: 2,
                count: -2.0
            })
        );
        for s in tactile_scenario::SHIPPED_HISTOGRAMS {
            let spec = format!("name = \"{}\"", s.name);
            let [_, b] = load(&with_histogram(&spec), dir.path()).expect(s.name);
            // At 1 kHz a sample is a ms: the 5G delays reach 2.0 to 17.1 ms.
            let bound = b.expect("loaded").bound();
            assert!((2.0..=17.1).contains(&bound), "{}: {bound}", s.name);
        }
    }
}
