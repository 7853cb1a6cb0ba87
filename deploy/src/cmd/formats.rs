//! The output format options `tactile run`, `report` and `sweep` share.

use clap::Args;
use tactile_report::error::UnknownChoice;
use tactile_report::mcap::Compression;
use tactile_report::write::TraceFormat;

/// Which trace files a report writes and how run.mcap is compressed.
#[derive(Debug, Clone, Args)]
pub struct FormatArgs {
    /// The trace's files: csv (trace.csv, the default: any tool and any diff reads
    /// it), parquet (trace.parquet, columnar with zstd: a fifth of the CSV's size,
    /// loaded by pandas in a fraction of its time) or both. The same columns and values.
    #[arg(long, value_name = "csv|parquet|both", default_value = "csv", value_parser = parse_trace)]
    pub trace_format: TraceFormat,
    /// run.mcap's chunk compression: lz4 (the default, the faster) or zstd (the
    /// smaller); Foxglove, the mcap CLI and rosbag2 read both.
    #[arg(long, value_name = "lz4|zstd", default_value = "lz4", value_parser = parse_mcap)]
    pub mcap_compression: Compression,
}

fn parse_trace(s: &str) -> Result<TraceFormat, UnknownChoice> {
    s.parse()
}

fn parse_mcap(s: &str) -> Result<Compression, UnknownChoice> {
    s.parse()
}

impl FormatArgs {
    /// The first format option given another value than its default, if any.
    fn given(&self) -> Option<&'static str> {
        if self.trace_format != TraceFormat::Csv {
            Some("--trace-format")
        } else if self.mcap_compression != Compression::Lz4 {
            Some("--mcap-compression")
        } else {
            None
        }
    }

    /// Refuses a format option that would change nothing (`writes`: the command writes
    /// the trace and the recording), so a study does not find out at its end that its
    /// Parquet traces were never written.
    pub fn refuse_unless(
        &self,
        writes: bool,
        why: &str,
    ) -> Result<(), tactile_launch::error::Error> {
        match self.given() {
            Some(flag) if !writes => Err(tactile_launch::error::Error::BadInput(format!(
                "{flag} {why}: no trace and no recording are written"
            ))),
            _ => Ok(()),
        }
    }

    /// The launcher's outputs for these options.
    pub fn outputs(&self, no_trace: bool) -> tactile_launch::Outputs {
        tactile_launch::Outputs {
            no_trace,
            trace_format: self.trace_format,
            mcap_compression: self.mcap_compression,
            trace_columns: Vec::new(),
        }
    }
}
