//! A Parquet table of the few column types a LeRobot dataset uses, written with
//! parquet's column writers (no Arrow: the trace's stack, [`crate::parquet_trace`]):
//! integers, floats, strings, optional floats and flags, and lists (a vector per row,
//! as `observation.state`). Rows are held until [`Table::flush`] writes them as one
//! row group, so a caller bounds memory by flushing every so many rows.

use crate::parquet_trace::other;
use parquet::basic::{Compression, LogicalType, Repetition, Type as PhysicalType, ZstdLevel};
use parquet::column::writer::ColumnWriter;
use parquet::data_type::ByteArray;
use parquet::file::metadata::KeyValue;
use parquet::file::properties::WriterProperties;
use parquet::file::writer::SerializedFileWriter;
use parquet::schema::types::Type;
use std::io;
use std::path::Path;
use std::sync::Arc;

/// A column's type as pyarrow reads it back.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Col {
    /// int64.
    I64,
    /// float (32 bits).
    F32,
    /// double, null where absent.
    OptF64,
    /// int64, null where absent.
    OptI64,
    /// bool, null where absent.
    OptBool,
    /// string (UTF-8).
    Str,
    /// list<float>.
    ListF32,
    /// list<double>.
    ListF64,
    /// list<int64>.
    ListI64,
    /// list<string>.
    ListStr,
}

/// One row's value of a column.
#[derive(Debug, Clone, PartialEq)]
pub enum Cell {
    /// An integer.
    I64(i64),
    /// A float (F32 columns).
    F32(f32),
    /// A double or null.
    OptF64(Option<f64>),
    /// An integer or null.
    OptI64(Option<i64>),
    /// A flag or null.
    OptBool(Option<bool>),
    /// A text.
    Str(String),
    /// Floats.
    ListF32(Vec<f32>),
    /// Doubles.
    ListF64(Vec<f64>),
    /// Integers.
    ListI64(Vec<i64>),
    /// Texts.
    ListStr(Vec<String>),
}

/// A column's values so far, with their definition and repetition levels.
#[derive(Debug, Default)]
struct Held {
    i64s: Vec<i64>,
    f32s: Vec<f32>,
    f64s: Vec<f64>,
    bools: Vec<bool>,
    texts: Vec<ByteArray>,
    def: Vec<i16>,
    rep: Vec<i16>,
}

impl Held {
    fn clear(&mut self) {
        self.i64s.clear();
        self.f32s.clear();
        self.f64s.clear();
        self.bools.clear();
        self.texts.clear();
        self.def.clear();
        self.rep.clear();
    }

    /// The levels of a list's entries: each defined, the first starting a row (an
    /// empty list: one undefined level, its row started).
    fn list(&mut self, len: usize) {
        if len == 0 {
            self.def.push(0);
            self.rep.push(0);
            return;
        }
        self.def.extend(std::iter::repeat_n(1, len));
        self.rep.push(0);
        self.rep.extend(std::iter::repeat_n(1, len - 1));
    }
}

/// A Parquet file being written, one row group per [`Table::flush`].
pub struct Table {
    writer: SerializedFileWriter<std::fs::File>,
    cols: Vec<(String, Col)>,
    held: Vec<Held>,
    rows: usize,
    /// Bytes of values handed to the writer so far (LeRobot's file size rule counts
    /// uncompressed bytes).
    pub bytes: u64,
}

impl std::fmt::Debug for Table {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Table").field("cols", &self.cols).finish()
    }
}

fn primitive(
    name: &str,
    physical: PhysicalType,
    logical: Option<LogicalType>,
    repetition: Repetition,
) -> io::Result<Arc<Type>> {
    Type::primitive_type_builder(name, physical)
        .with_repetition(repetition)
        .with_logical_type(logical)
        .build()
        .map(Arc::new)
        .map_err(other)
}

/// A required list of `physical` elements, in the three-level form every reader knows.
fn list(name: &str, physical: PhysicalType, logical: Option<LogicalType>) -> io::Result<Arc<Type>> {
    let element = primitive("element", physical, logical, Repetition::REQUIRED)?;
    let middle = Type::group_type_builder("list")
        .with_repetition(Repetition::REPEATED)
        .with_fields(vec![element])
        .build()
        .map_err(other)?;
    Type::group_type_builder(name)
        .with_repetition(Repetition::REQUIRED)
        .with_logical_type(Some(LogicalType::List))
        .with_fields(vec![Arc::new(middle)])
        .build()
        .map(Arc::new)
        .map_err(other)
}

fn field(name: &str, col: Col) -> io::Result<Arc<Type>> {
    use PhysicalType as P;
    const OPTIONAL: Repetition = Repetition::OPTIONAL;
    const REQUIRED: Repetition = Repetition::REQUIRED;
    let text = Some(LogicalType::String);
    match col {
        Col::I64 => primitive(name, P::INT64, None, REQUIRED),
        Col::F32 => primitive(name, P::FLOAT, None, REQUIRED),
        Col::OptF64 => primitive(name, P::DOUBLE, None, OPTIONAL),
        Col::OptI64 => primitive(name, P::INT64, None, OPTIONAL),
        Col::OptBool => primitive(name, P::BOOLEAN, None, OPTIONAL),
        Col::Str => primitive(name, P::BYTE_ARRAY, text, REQUIRED),
        Col::ListF32 => list(name, P::FLOAT, None),
        Col::ListF64 => list(name, P::DOUBLE, None),
        Col::ListI64 => list(name, P::INT64, None),
        Col::ListStr => list(name, P::BYTE_ARRAY, text),
    }
}

impl Table {
    /// Starts the file at `path` with these columns.
    pub fn create(path: &Path, cols: Vec<(String, Col)>) -> io::Result<Table> {
        let fields = cols
            .iter()
            .map(|(n, c)| field(n, *c))
            .collect::<io::Result<Vec<_>>>()?;
        let schema = Type::group_type_builder("schema")
            .with_fields(fields)
            .build()
            .map_err(other)?;
        let level = ZstdLevel::try_new(crate::parquet_trace::LEVEL).map_err(other)?;
        let props = WriterProperties::builder()
            .set_compression(Compression::ZSTD(level))
            .set_dictionary_enabled(false)
            .set_created_by(format!("tactile {}", env!("CARGO_PKG_VERSION")))
            .build();
        let file = std::fs::File::create(path)?;
        let writer =
            SerializedFileWriter::new(file, Arc::new(schema), Arc::new(props)).map_err(other)?;
        let held = cols.iter().map(|_| Held::default()).collect();
        Ok(Table {
            writer,
            cols,
            held,
            rows: 0,
            bytes: 0,
        })
    }

    /// Rows held, not yet flushed.
    pub fn rows(&self) -> usize {
        self.rows
    }

    /// Adds a row: one cell per column, in the columns' order and of their types.
    pub fn add(&mut self, row: &[Cell]) -> io::Result<()> {
        if row.len() != self.cols.len() {
            return Err(io::Error::other(format!(
                "a row of {} cells for {} columns",
                row.len(),
                self.cols.len()
            )));
        }
        for ((cell, h), (name, col)) in row.iter().zip(&mut self.held).zip(&self.cols) {
            let bytes = match (cell, col) {
                (Cell::I64(x), Col::I64) => {
                    h.i64s.push(*x);
                    8
                }
                (Cell::F32(x), Col::F32) => {
                    h.f32s.push(*x);
                    4
                }
                (Cell::OptF64(x), Col::OptF64) => {
                    h.def.push(i16::from(x.is_some()));
                    h.f64s.extend(x);
                    8
                }
                (Cell::OptI64(x), Col::OptI64) => {
                    h.def.push(i16::from(x.is_some()));
                    h.i64s.extend(x);
                    8
                }
                (Cell::OptBool(x), Col::OptBool) => {
                    h.def.push(i16::from(x.is_some()));
                    h.bools.extend(x);
                    1
                }
                (Cell::Str(s), Col::Str) => {
                    h.texts.push(ByteArray::from(s.as_str()));
                    s.len() + 4
                }
                (Cell::ListF32(v), Col::ListF32) => {
                    h.list(v.len());
                    h.f32s.extend(v);
                    4 * v.len()
                }
                (Cell::ListF64(v), Col::ListF64) => {
                    h.list(v.len());
                    h.f64s.extend(v);
                    8 * v.len()
                }
                (Cell::ListI64(v), Col::ListI64) => {
                    h.list(v.len());
                    h.i64s.extend(v);
                    8 * v.len()
                }
                (Cell::ListStr(v), Col::ListStr) => {
                    h.list(v.len());
                    h.texts
                        .extend(v.iter().map(|s| ByteArray::from(s.as_str())));
                    v.iter().map(|s| s.len() + 4).sum()
                }
                _ => {
                    return Err(io::Error::other(format!(
                        "column {name}: a value of another type ({cell:?} for {col:?})"
                    )))
                }
            };
            self.bytes += bytes as u64;
        }
        self.rows += 1;
        Ok(())
    }

    /// Writes the rows held as one row group.
    pub fn flush(&mut self) -> io::Result<()> {
        if self.rows == 0 {
            return Ok(());
        }
        let mut group = self.writer.next_row_group().map_err(other)?;
        let mut held = self.held.iter();
        while let Some(mut col) = group.next_column().map_err(other)? {
            let h = held
                .next()
                .ok_or_else(|| io::Error::other("more columns than the table's"))?;
            let def = (!h.def.is_empty()).then_some(&h.def[..]);
            let rep = (!h.rep.is_empty()).then_some(&h.rep[..]);
            let written = match col.untyped() {
                ColumnWriter::Int64ColumnWriter(w) => w.write_batch(&h.i64s, def, rep),
                ColumnWriter::FloatColumnWriter(w) => w.write_batch(&h.f32s, def, rep),
                ColumnWriter::DoubleColumnWriter(w) => w.write_batch(&h.f64s, def, rep),
                ColumnWriter::BoolColumnWriter(w) => w.write_batch(&h.bools, def, rep),
                ColumnWriter::ByteArrayColumnWriter(w) => w.write_batch(&h.texts, def, rep),
                _ => {
                    return Err(io::Error::other(
                        "a column of a type the table does not write",
                    ))
                }
            };
            written.map_err(other)?;
            col.close().map_err(other)?;
        }
        group.close().map_err(other)?;
        self.held.iter_mut().for_each(Held::clear);
        self.rows = 0;
        Ok(())
    }

    /// Writes the last rows, `metadata` (key, value) into the footer, and closes.
    pub fn finish(mut self, metadata: &[(&str, String)]) -> io::Result<()> {
        self.flush()?;
        for (k, v) in metadata {
            self.writer
                .append_key_value_metadata(KeyValue::new((*k).to_string(), v.clone()));
        }
        self.writer.close().map_err(other)?;
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_cell_of_another_type_is_refused() {
        let dir = tempfile::tempdir().expect("tmp");
        let mut t =
            Table::create(&dir.path().join("t.parquet"), vec![("a".into(), Col::I64)]).expect("t");
        assert!(t.add(&[Cell::F32(1.0)]).is_err());
        assert!(t.add(&[]).is_err());
        t.add(&[Cell::I64(1)]).expect("row");
        t.finish(&[]).expect("finish");
    }
}
