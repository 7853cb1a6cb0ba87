//! The numeric CSV both `tactile kernels` and trajectory files use: a header row naming
//! the columns, then rows of finite numbers. Errors name the line and the column, so a
//! user can find the bad cell; blank lines are skipped.

use thiserror::Error;

/// A CSV problem, located.
#[derive(Debug, Error, PartialEq, Eq)]
pub enum CsvError {
    /// No header at all.
    #[error("line 1: empty input, expected the header {expected}")]
    Empty {
        /// The expected header.
        expected: String,
    },
    /// The header names other columns.
    #[error("line {line}: header is {found:?}, expected {expected}")]
    Header {
        /// 1-based line number.
        line: usize,
        /// What the header said.
        found: String,
        /// What it should say.
        expected: String,
    },
    /// A row with too few or too many cells (a truncated line, for example).
    #[error("line {line}: expected {expected} columns ({names}), found {found}")]
    Columns {
        /// 1-based line number.
        line: usize,
        /// Columns expected.
        expected: usize,
        /// Their names, comma separated.
        names: String,
        /// Columns found.
        found: usize,
    },
    /// A cell that is not a finite number.
    #[error("line {line}, column {column} ({name}): {text:?} is not a {what}")]
    Cell {
        /// 1-based line number.
        line: usize,
        /// 1-based column number.
        column: usize,
        /// Column name.
        name: String,
        /// The cell's text.
        text: String,
        /// "number" or "finite number".
        what: &'static str,
    },
    /// The source could not be read (not UTF-8, an I/O error) at this line.
    #[error("line {line}: {problem}")]
    Read {
        /// 1-based line number.
        line: usize,
        /// What went wrong.
        problem: String,
    },
}

/// Longest text of a bad cell or header an error quotes: the rest is elided, so a
/// line of garbage gives a readable message, not a megabyte.
pub const QUOTED: usize = 40;

/// `text` cut to [`QUOTED`] characters, with `...` when cut.
pub fn shortened(text: &str) -> String {
    match text.char_indices().nth(QUOTED) {
        Some((at, _)) => format!("{}...", &text[..at]),
        None => text.to_string(),
    }
}

/// Checks a header line (already known to be line `line`) against `columns`.
pub fn check_header(line: usize, text: &str, columns: &[&str]) -> Result<(), CsvError> {
    let got: Vec<&str> = text.split(',').map(str::trim).collect();
    if got != columns {
        return Err(CsvError::Header {
            line,
            found: shortened(text.trim()),
            expected: columns.join(","),
        });
    }
    Ok(())
}

/// Parses one data row into `out` (cleared first).
pub fn parse_row(
    line: usize,
    text: &str,
    columns: &[&str],
    out: &mut Vec<f64>,
) -> Result<(), CsvError> {
    out.clear();
    let cells: Vec<&str> = text.split(',').map(str::trim).collect();
    if cells.len() != columns.len() {
        return Err(CsvError::Columns {
            line,
            expected: columns.len(),
            names: columns.join(","),
            found: cells.len(),
        });
    }
    for (k, (cell, name)) in cells.iter().zip(columns).enumerate() {
        let bad = |what| CsvError::Cell {
            line,
            column: k + 1,
            name: (*name).to_string(),
            text: shortened(cell),
            what,
        };
        match cell.parse::<f64>() {
            Ok(v) if v.is_finite() => out.push(v),
            Ok(_) => return Err(bad("finite number")),
            Err(_) => return Err(bad("number")),
        }
    }
    Ok(())
}

/// Parses a whole document with header `columns` into rows.
pub fn parse(text: &str, columns: &[&str]) -> Result<Vec<Vec<f64>>, CsvError> {
    let (_, rows) = parse_located(text, &[columns])?;
    Ok(rows.into_iter().map(|(_, r)| r).collect())
}

/// Rows with their 1-based line numbers.
pub type LocatedRows = Vec<(usize, Vec<f64>)>;

/// Parses a document whose header is one of `headers` (a file format with optional
/// columns, such as a trajectory with or without its time column). Returns which
/// header it had and each row with its 1-based line number, so that checks across
/// rows (times that must increase) can name the line too.
pub fn parse_located(text: &str, headers: &[&[&str]]) -> Result<(usize, LocatedRows), CsvError> {
    let mut reader = Rows::new(text_lines(text), headers)?;
    let mut rows = Vec::new();
    while let Some((line, row)) = reader.next_row()? {
        rows.push((line, row.to_vec()));
    }
    Ok((reader.which, rows))
}

/// The lines of a text, numbered from 1, for [`Rows`].
pub fn text_lines(text: &str) -> impl Iterator<Item = Result<(usize, &str), CsvError>> {
    text.lines().enumerate().map(|(i, l)| Ok((i + 1, l)))
}

/// The lines of a reader, numbered from 1, for [`Rows`]: a file is read a line at a
/// time, so only the rows' values are kept, never the whole text (a file's text and
/// its rows as vectors took ten times the file's size).
pub fn reader_lines(
    r: impl std::io::BufRead,
) -> impl Iterator<Item = Result<(usize, String), CsvError>> {
    r.lines().enumerate().map(|(i, l)| {
        l.map(|l| (i + 1, l)).map_err(|e| CsvError::Read {
            line: i + 1,
            problem: match e.kind() {
                std::io::ErrorKind::InvalidData => "not UTF-8 text".to_string(),
                _ => e.to_string(),
            },
        })
    })
}

/// A document's rows, one at a time, after its header: what reads a large file
/// keeps each row's values where they belong instead of a vector per row.
#[derive(Debug)]
pub struct Rows<'h, L> {
    /// Which of the headers the document has (its index).
    pub which: usize,
    columns: &'h [&'h str],
    lines: L,
    row: Vec<f64>,
}

impl<'h, S: AsRef<str>, L: Iterator<Item = Result<(usize, S), CsvError>>> Rows<'h, L> {
    /// Reads the header, which must be one of `headers` (blank lines are skipped).
    pub fn new(mut lines: L, headers: &'h [&'h [&'h str]]) -> Result<Self, CsvError> {
        let expected = || {
            let names: Vec<String> = headers.iter().map(|h| h.join(",")).collect();
            names.join(" or ")
        };
        let (hl, header) = next_filled(&mut lines)?.ok_or_else(|| CsvError::Empty {
            expected: expected(),
        })?;
        let header = header.as_ref();
        let which = headers
            .iter()
            .position(|h| check_header(hl, header, h).is_ok())
            .ok_or_else(|| CsvError::Header {
                line: hl,
                found: shortened(header.trim()),
                expected: expected(),
            })?;
        let columns = headers[which];
        Ok(Rows {
            which,
            columns,
            lines,
            row: Vec::with_capacity(columns.len()),
        })
    }

    /// The next data row and its line number, `None` at the end.
    pub fn next_row(&mut self) -> Result<Option<(usize, &[f64])>, CsvError> {
        let Some((line, text)) = next_filled(&mut self.lines)? else {
            return Ok(None);
        };
        parse_row(line, text.as_ref(), self.columns, &mut self.row)?;
        Ok(Some((line, &self.row)))
    }
}

/// The next line that is not blank.
fn next_filled<S: AsRef<str>>(
    lines: &mut impl Iterator<Item = Result<(usize, S), CsvError>>,
) -> Result<Option<(usize, S)>, CsvError> {
    for l in lines {
        let (n, text) = l?;
        if !text.as_ref().trim().is_empty() {
            return Ok(Some((n, text)));
        }
    }
    Ok(None)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_bad_cell_is_quoted_short() {
        let long = "x".repeat(10_000);
        let e = parse_row(3, &format!("1,{long},2"), &["a", "b", "c"], &mut Vec::new());
        let text = e.expect_err("not a number").to_string();
        assert!(
            text.len() < 120 && text.contains("xxx...") && text.contains("line 3"),
            "{text}"
        );
        assert_eq!(shortened("short"), "short");
    }

    #[test]
    fn parses_and_locates_errors() {
        let cols = ["x", "y", "z"];
        assert_eq!(
            parse("x,y,z\n1,2,3\n\n4, 5 ,6\n", &cols),
            Ok(vec![vec![1.0, 2.0, 3.0], vec![4.0, 5.0, 6.0]])
        );
        let e = parse("x,y,z\n1,2,3\n1,zz,3\n", &cols).expect_err("malformed");
        assert_eq!(
            e.to_string(),
            "line 3, column 2 (y): \"zz\" is not a number"
        );
        let e = parse("x,y,z\n1,2\n", &cols).expect_err("malformed");
        assert_eq!(e.to_string(), "line 2: expected 3 columns (x,y,z), found 2");
        let e = parse("x,y,z\n1,NaN,2\n", &cols).expect_err("malformed");
        assert!(e.to_string().contains("not a finite number"));
        let e = parse("a,b,c\n", &cols).expect_err("malformed");
        assert!(matches!(e, CsvError::Header { line: 1, .. }));
        assert!(matches!(parse("\n\n", &cols), Err(CsvError::Empty { .. })));
    }

    #[test]
    fn one_of_several_headers_and_rows_with_their_lines() {
        let both: [&[&str]; 2] = [&["x", "y", "z"], &["t", "x", "y", "z"]];
        assert_eq!(
            parse_located("t,x,y,z\n0,1,2,3\n\n0.5,4,5,6\n", &both),
            Ok((
                1,
                vec![(2, vec![0.0, 1.0, 2.0, 3.0]), (4, vec![0.5, 4.0, 5.0, 6.0])]
            ))
        );
        assert_eq!(parse_located("x,y,z\n", &both), Ok((0, vec![])));
        let e = parse_located("t,x,y\n", &both).expect_err("no such header");
        assert_eq!(
            e.to_string(),
            "line 1: header is \"t,x,y\", expected x,y,z or t,x,y,z"
        );
        let e = parse_located("t,x,y,z\n1,2,3\n", &both).expect_err("short row");
        assert_eq!(
            e.to_string(),
            "line 2: expected 4 columns (t,x,y,z), found 3"
        );
    }

    #[test]
    fn a_reader_gives_the_same_rows_and_names_bad_bytes() {
        let both: [&[&str]; 2] = [&["x", "y", "z"], &["t", "x", "y", "z"]];
        let text = "\nt,x,y,z\n0,1,2,3\n\n0.5,4,5,6\n";
        let mut r = Rows::new(reader_lines(text.as_bytes()), &both).expect("header");
        assert_eq!(r.which, 1);
        assert_eq!(r.next_row(), Ok(Some((3, &[0.0, 1.0, 2.0, 3.0][..]))));
        assert_eq!(r.next_row(), Ok(Some((5, &[0.5, 4.0, 5.0, 6.0][..]))));
        assert_eq!(r.next_row(), Ok(None));
        let bad: &[u8] = b"x,y,z\n1,2,3\n\xff,2,3\n";
        let mut r = Rows::new(reader_lines(bad), &both).expect("header");
        assert!(r.next_row().is_ok());
        let e = r.next_row().expect_err("not UTF-8");
        assert_eq!(e.to_string(), "line 3: not UTF-8 text");
    }
}
