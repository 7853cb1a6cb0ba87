//! A trace's rows as typed columns, for the columnar files (`trace.parquet`): each
//! trace field says its columns' kinds and pushes its values ([`crate::trace`]), so
//! the Parquet trace has exactly the CSV's columns, in the same order.

/// The type of one column.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Kind {
    /// Unsigned 64-bit integer (sample numbers, stamps).
    U64,
    /// Unsigned 32-bit integer (flags, delays in samples).
    U32,
    /// Signed 64-bit integer.
    I64,
    /// IEEE double.
    F64,
    /// True or false (`0` or `1` in the CSV).
    Bool,
}

/// One column's values so far. Unsigned values are kept in their signed twins' bits:
/// Parquet stores them so, and the schema's logical type says they are unsigned.
#[derive(Debug, Clone, PartialEq)]
pub enum Values {
    /// `U64` and `I64` columns.
    I64(Vec<i64>),
    /// `U32` columns.
    I32(Vec<i32>),
    /// `F64` columns.
    F64(Vec<f64>),
    /// `Bool` columns.
    Bool(Vec<bool>),
}

impl Values {
    /// Values held.
    pub fn len(&self) -> usize {
        match self {
            Values::I64(v) => v.len(),
            Values::I32(v) => v.len(),
            Values::F64(v) => v.len(),
            Values::Bool(v) => v.len(),
        }
    }

    /// True if none.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }
}

/// Columns being filled row by row: each push goes into the next column of the row.
#[derive(Debug, Clone, PartialEq)]
pub struct Columns {
    /// Names and kinds, in order.
    pub names: Vec<(String, Kind)>,
    /// The values, one entry per column.
    pub values: Vec<Values>,
    at: usize,
}

impl Columns {
    /// Empty columns of these names and kinds.
    pub fn new(names: Vec<(String, Kind)>) -> Columns {
        let values = names
            .iter()
            .map(|(_, k)| match k {
                Kind::U64 | Kind::I64 => Values::I64(Vec::new()),
                Kind::U32 => Values::I32(Vec::new()),
                Kind::F64 => Values::F64(Vec::new()),
                Kind::Bool => Values::Bool(Vec::new()),
            })
            .collect();
        Columns {
            names,
            values,
            at: 0,
        }
    }

    fn next(&mut self) -> Option<&mut Values> {
        let v = self.values.get_mut(self.at);
        self.at += 1;
        v
    }

    /// The next column's value (an unsigned one as its bits).
    pub fn i64(&mut self, x: i64) {
        if let Some(Values::I64(v)) = self.next() {
            v.push(x);
        }
    }

    /// The next column's value (as its bits).
    pub fn i32(&mut self, x: i32) {
        if let Some(Values::I32(v)) = self.next() {
            v.push(x);
        }
    }

    /// The next column's value.
    pub fn f64(&mut self, x: f64) {
        if let Some(Values::F64(v)) = self.next() {
            v.push(x);
        }
    }

    /// The next column's value.
    pub fn bool(&mut self, x: bool) {
        if let Some(Values::Bool(v)) = self.next() {
            v.push(x);
        }
    }

    /// Ends a row: the next push goes into the first column again.
    pub fn end_row(&mut self) {
        debug_assert_eq!(self.at, self.names.len(), "a row filled every column");
        self.at = 0;
    }

    /// Rows held (of the first column: [`Columns::whole`] says whether all agree).
    pub fn rows(&self) -> usize {
        self.values.first().map_or(0, Values::len)
    }

    /// True if every column holds the same number of values (no push went astray).
    pub fn whole(&self) -> bool {
        let rows = self.rows();
        self.values.iter().all(|v| v.len() == rows)
    }

    /// Empties every column (kinds kept).
    pub fn clear(&mut self) {
        for v in &mut self.values {
            match v {
                Values::I64(v) => v.clear(),
                Values::I32(v) => v.clear(),
                Values::F64(v) => v.clear(),
                Values::Bool(v) => v.clear(),
            }
        }
        self.at = 0;
    }
}
