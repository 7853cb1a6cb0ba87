//! `trace.parquet`: the trace in Apache Parquet (columnar, zstd), the same columns and
//! values as `trace.csv` ([`crate::trace`]'s one list), for pandas, Polars, DuckDB
//! and Arrow: a million rows load in a fraction of the CSV's time and take a fraction
//! of its size. Rows are gathered in row groups of [`ROW_GROUP`], so memory stays
//! bounded however long the run.
//!
//! A sweep adds its combination as constant text columns (`control.kind`, ...), so
//! the traces of all its runs read as one table (`pandas.read_parquet` of the
//! sweep's `traces/` folder).

use crate::columns::{Columns, Kind, Values};
use crate::trace::{self, TraceRow};
use parquet::basic::{Compression, ZstdLevel};
use parquet::column::writer::ColumnWriter;
use parquet::data_type::ByteArray;
use parquet::file::properties::WriterProperties;
use parquet::file::writer::SerializedFileWriter;
use std::io;
use std::path::Path;
use std::sync::Arc;

/// Rows per row group: about 13 MB of values in memory (170 columns of 8 bytes).
pub const ROW_GROUP: usize = 10_000;

/// zstd's level for the pages: 3, zstd's default (1 is a few percent larger here).
pub const LEVEL: i32 = 3;

fn other(e: parquet::errors::ParquetError) -> io::Error {
    io::Error::other(e.to_string())
}

/// The schema's text: the trace's columns, then the constant text columns.
fn schema(kinds: &[(String, Kind)], extra: &[(String, String)]) -> String {
    let mut s = String::from("message trace {\n");
    for (name, kind) in kinds {
        s += &format!("  required {} {name}{};\n", kind.physical(), kind.logical());
    }
    for (name, _) in extra {
        s += &format!("  required binary {} (STRING);\n", name);
    }
    s + "}\n"
}

/// A `trace.parquet` being written.
pub struct ParquetTrace {
    writer: SerializedFileWriter<std::fs::File>,
    cols: Columns,
    extra: Vec<(String, String)>,
}

impl std::fmt::Debug for ParquetTrace {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("ParquetTrace")
            .field("rows", &self.cols.rows())
            .finish()
    }
}

impl ParquetTrace {
    /// Starts the file at `path`, with `extra` constant text columns (name, value)
    /// after the trace's; a name must be a plain identifier or dotted key.
    pub fn create(path: &Path, extra: Vec<(String, String)>) -> io::Result<ParquetTrace> {
        if let Some((bad, _)) = extra.iter().find(|(n, _)| !plain(n)) {
            return Err(io::Error::new(
                io::ErrorKind::InvalidInput,
                format!("{bad:?}: a trace column is named with letters, digits, '_' and '.'"),
            ));
        }
        let kinds = trace::kinds();
        let schema =
            parquet::schema::parser::parse_message_type(&schema(&kinds, &extra)).map_err(other)?;
        let level = ZstdLevel::try_new(LEVEL).map_err(other)?;
        let props = WriterProperties::builder()
            .set_compression(Compression::ZSTD(level))
            // Floats of a loop rarely repeat: dictionaries would be tried and dropped.
            .set_dictionary_enabled(false)
            .set_created_by(format!("tactile {}", env!("CARGO_PKG_VERSION")))
            .build();
        let file = std::fs::File::create(path)?;
        let writer =
            SerializedFileWriter::new(file, Arc::new(schema), Arc::new(props)).map_err(other)?;
        Ok(ParquetTrace {
            writer,
            cols: Columns::new(kinds),
            extra,
        })
    }

    /// Adds a row; `t0` is subtracted from its stamps (as in the CSV).
    pub fn add(&mut self, row: &TraceRow, t0: u64) -> io::Result<()> {
        row.push(&mut self.cols, t0);
        self.cols.end_row();
        if self.cols.rows() >= ROW_GROUP {
            self.flush_group()?;
        }
        Ok(())
    }

    /// Writes the rows held as one row group.
    fn flush_group(&mut self) -> io::Result<()> {
        let rows = self.cols.rows();
        if rows == 0 {
            return Ok(());
        }
        let mut group = self.writer.next_row_group().map_err(other)?;
        let texts: Vec<Vec<ByteArray>> = self
            .extra
            .iter()
            .map(|(_, v)| vec![ByteArray::from(v.as_str()); rows])
            .collect();
        let mut values = self
            .cols
            .values
            .iter()
            .map(Some)
            .chain(texts.iter().map(|_| None));
        let mut texts = texts.iter();
        while let Some(mut col) = group.next_column().map_err(other)? {
            let written = match (values.next().flatten(), col.untyped()) {
                (Some(Values::I64(v)), ColumnWriter::Int64ColumnWriter(w)) => {
                    w.write_batch(v, None, None)
                }
                (Some(Values::I32(v)), ColumnWriter::Int32ColumnWriter(w)) => {
                    w.write_batch(v, None, None)
                }
                (Some(Values::F64(v)), ColumnWriter::DoubleColumnWriter(w)) => {
                    w.write_batch(v, None, None)
                }
                (Some(Values::Bool(v)), ColumnWriter::BoolColumnWriter(w)) => {
                    w.write_batch(v, None, None)
                }
                (None, ColumnWriter::ByteArrayColumnWriter(w)) => match texts.next() {
                    Some(t) => w.write_batch(t, None, None),
                    None => return Err(io::Error::other("a text column without values")),
                },
                _ => {
                    return Err(io::Error::other(
                        "a trace column of another type than its schema",
                    ))
                }
            };
            written.map_err(other)?;
            col.close().map_err(other)?;
        }
        group.close().map_err(other)?;
        self.cols.clear();
        Ok(())
    }

    /// Writes the last row group and the footer.
    pub fn finish(mut self) -> io::Result<()> {
        self.flush_group()?;
        self.writer.close().map_err(other)?;
        Ok(())
    }
}

/// A name the schema's text can carry as it is.
fn plain(name: &str) -> bool {
    !name.is_empty()
        && name
            .chars()
            .all(|c| c.is_ascii_alphanumeric() || c == '_' || c == '.')
}

/// The trace's column names, as the CSV's header has them (for the tests).
pub fn names() -> Vec<String> {
    trace::kinds().into_iter().map(|(n, _)| n).collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_parquet_columns_are_the_csvs() {
        let h = trace::header();
        assert_eq!(names(), h.split(',').collect::<Vec<_>>());
    }

    #[test]
    fn a_column_name_the_schema_cannot_carry_is_refused() {
        let dir = tempfile::tempdir().expect("tempdir");
        let e = ParquetTrace::create(
            &dir.path().join("t.parquet"),
            vec![("a b".into(), "x".into())],
        )
        .expect_err("refused");
        assert!(e.to_string().contains("\"a b\""), "{e}");
    }
}
