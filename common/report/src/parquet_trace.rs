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
use parquet::basic::{Compression, LogicalType, Repetition, Type as PhysicalType, ZstdLevel};
use parquet::column::writer::ColumnWriter;
use parquet::data_type::ByteArray;
use parquet::file::properties::WriterProperties;
use parquet::file::writer::SerializedFileWriter;
use parquet::schema::types::Type;
use std::io;
use std::path::Path;
use std::sync::Arc;

/// Rows per row group: about 7.5 MB of values in memory (94 columns of at most 8 bytes).
pub const ROW_GROUP: usize = 10_000;

/// zstd's level for the pages: 3, zstd's default (1 is a few percent larger here).
pub const LEVEL: i32 = 3;

pub(crate) fn other(e: parquet::errors::ParquetError) -> io::Error {
    io::Error::other(e.to_string())
}

/// The schema: the trace's columns, then the constant text columns. Built field by
/// field, so a column may be named anything (a sweep's `environment.objects[0].stiffness`).
fn schema(kinds: &[(String, Kind)], extra: &[(String, String)]) -> io::Result<Type> {
    let mut fields = Vec::with_capacity(kinds.len() + extra.len());
    for (name, kind) in kinds {
        let (physical, logical) = match kind {
            Kind::U64 => (PhysicalType::INT64, Some(unsigned(64))),
            Kind::U32 => (PhysicalType::INT32, Some(unsigned(32))),
            Kind::I64 => (PhysicalType::INT64, None),
            Kind::F64 => (PhysicalType::DOUBLE, None),
            Kind::Bool => (PhysicalType::BOOLEAN, None),
        };
        fields.push(field(name, physical, logical)?);
    }
    for (name, _) in extra {
        fields.push(field(
            name,
            PhysicalType::BYTE_ARRAY,
            Some(LogicalType::String),
        )?);
    }
    Type::group_type_builder("trace")
        .with_fields(fields)
        .build()
        .map_err(other)
}

fn unsigned(bit_width: i8) -> LogicalType {
    LogicalType::Integer(parquet::basic::IntType {
        bit_width,
        is_signed: false,
    })
}

/// A required column.
fn field(
    name: &str,
    physical: PhysicalType,
    logical: Option<LogicalType>,
) -> io::Result<Arc<Type>> {
    Type::primitive_type_builder(name, physical)
        .with_repetition(Repetition::REQUIRED)
        .with_logical_type(logical)
        .build()
        .map(Arc::new)
        .map_err(other)
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
    /// after the trace's.
    pub fn create(path: &Path, extra: Vec<(String, String)>) -> io::Result<ParquetTrace> {
        let kinds = trace::kinds();
        let schema = schema(&kinds, &extra)?;
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
        if !self.cols.whole() {
            return Err(io::Error::other(
                "a trace row did not fill its columns (a column of another type)",
            ));
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

#[cfg(test)]
mod tests {
    use super::*;

    /// The trace's column names, as the CSV's header has them (for the tests).
    fn names() -> Vec<String> {
        trace::kinds().into_iter().map(|(n, _)| n).collect()
    }

    #[test]
    fn the_parquet_columns_are_the_csvs() {
        let h = trace::header();
        assert_eq!(names(), h.split(',').collect::<Vec<_>>());
    }

    #[test]
    fn any_column_name_is_carried() {
        let dir = tempfile::tempdir().expect("tempdir");
        let extra = vec![("environment.objects[0].stiffness".into(), "[1, 2]".into())];
        let mut t = ParquetTrace::create(&dir.path().join("t.parquet"), extra).expect("create");
        t.add(&TraceRow::default(), 0).expect("row");
        t.finish().expect("finish");
    }
}
