//! `--set KEY=VALUE`: one change to a scenario, from the command line or a sweep.
//!
//! KEY is a dotted path into the scenario's TOML (`network.forward.delay`,
//! `environment.objects[0].stiffness`), VALUE a TOML value (`[0, 0, 0]`, `1000.0`,
//! `"lockstep"`; a bare word such as `lockstep` is taken as a string). The changed
//! text is then read like any scenario file, so an unknown key or a bad value gets the
//! same one-line error naming the field.

use toml::{Table, Value};

/// What is wrong with a `--set`, or with applying the sets to a scenario's text.
#[derive(Debug, thiserror::Error)]
pub enum SetError {
    /// No `=` in it.
    #[error("--set {text:?}: expected KEY=VALUE")]
    NoValue {
        /// The set as written.
        text: String,
    },
    /// Its key or its value is wrong.
    #[error("--set {text:?}: {source}")]
    Parse {
        /// The set as written.
        text: String,
        /// What is wrong.
        source: Problem,
    },
    /// Two sets of one time in two units.
    #[error("{}", twice(.0, .1))]
    Twice(String, String),
    /// The scenario's text is not TOML.
    #[error("the scenario is not TOML: {}", .0.message().trim_end())]
    NotToml(#[source] Box<toml::de::Error>),
    /// The set's path does not fit the scenario's tables.
    #[error("--set {text}: {source}")]
    Put {
        /// The set as written.
        text: String,
        /// Where it does not fit.
        source: Problem,
    },
    /// The changed table could not be written back as TOML.
    #[error("encoding the scenario: {0}")]
    Encode(#[from] toml::ser::Error),
}

/// What is wrong in one part of a `--set`: its key, its value, or the place it names.
#[derive(Debug, thiserror::Error)]
pub enum Problem {
    /// A segment of the key is not a name.
    #[error("{key:?} is not a dotted path of names (segment {seg:?})")]
    NotNames {
        /// The key.
        key: String,
        /// The segment.
        seg: String,
    },
    /// A `[` without its `]`.
    #[error("{key:?}: unclosed [ in {seg:?}")]
    Unclosed {
        /// The key.
        key: String,
        /// The segment.
        seg: String,
    },
    /// Not a number in `[...]`.
    #[error("{key:?}: [{idx}] is not an index")]
    NotIndex {
        /// The key.
        key: String,
        /// What is in the brackets.
        idx: String,
        /// Why it is no index.
        source: std::num::ParseIntError,
    },
    /// Something after a `]` that is not another `[`.
    #[error("{key:?}: unexpected {after:?} after ]")]
    After {
        /// The key.
        key: String,
        /// What follows.
        after: String,
    },
    /// Nothing after `=`.
    #[error("no value after =")]
    Empty,
    /// An integer TOML cannot hold.
    #[error(
        "{text} is out of range: a scenario's integers are {} to {}",
        i64::MIN,
        i64::MAX
    )]
    OutOfRange {
        /// The value.
        text: String,
    },
    /// Written as a number, but not one.
    #[error("{text:?} is not a number ({})", first_line(source))]
    NotNumber {
        /// The value.
        text: String,
        /// TOML's reason.
        source: Box<toml::de::Error>,
    },
    /// Neither a TOML value nor a bare word.
    #[error("{text:?} is not a TOML value ({})", first_line(source))]
    NotToml {
        /// The value.
        text: String,
        /// TOML's reason.
        source: Box<toml::de::Error>,
    },
    /// A path that starts with an index.
    #[error("the path must start with a key")]
    NoKey,
    /// An index past an array's end.
    #[error("{name}[{i}]: {name} has {len} entries")]
    NoEntry {
        /// The array.
        name: String,
        /// The index.
        i: usize,
        /// Its entries.
        len: usize,
    },
    /// A key under something that is no table.
    #[error("{name} is not a table, so it has no {key}")]
    NotTable {
        /// What is there.
        name: String,
        /// The key under it.
        key: String,
    },
    /// An index into something that is no array.
    #[error("{name} is not an array, so it has no [{i}]")]
    NotArray {
        /// What is there.
        name: String,
        /// The index.
        i: usize,
    },
}

/// The first line of TOML's message (the rest draws the text under it).
fn first_line(e: &toml::de::Error) -> &str {
    e.message().lines().next().unwrap_or("")
}

/// One `KEY=VALUE`.
#[derive(Debug, Clone, PartialEq)]
pub struct Set {
    /// The path, one entry per dotted segment: a key, then the array indices after it.
    pub path: Vec<Step>,
    /// The value.
    pub value: Value,
    /// As written, for messages.
    pub text: String,
}

/// One step of a path.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum Step {
    /// A key of a table.
    Key(String),
    /// An index into an array.
    Index(usize),
}

impl Set {
    /// Parses `KEY=VALUE`; the error says what is wrong with it.
    pub fn parse(text: &str) -> Result<Set, SetError> {
        let (key, value) = text.split_once('=').ok_or_else(|| SetError::NoValue {
            text: text.to_string(),
        })?;
        let parse = |source| SetError::Parse {
            text: text.to_string(),
            source,
        };
        Ok(Set {
            path: parse_path(key.trim()).map_err(parse)?,
            value: parse_value(value.trim()).map_err(parse)?,
            text: text.to_string(),
        })
    }

    /// The key as written.
    pub fn key(&self) -> String {
        self.text
            .split_once('=')
            .map_or_else(String::new, |(k, _)| k.trim().to_string())
    }
}

fn parse_path(key: &str) -> Result<Vec<Step>, Problem> {
    let mut path = Vec::new();
    for seg in key.split('.') {
        let (name, mut rest) = seg.split_once('[').map_or((seg, ""), |(n, r)| (n, r));
        let ok = !name.is_empty()
            && name
                .chars()
                .all(|c| c.is_ascii_alphanumeric() || c == '_' || c == '-');
        if !ok {
            return Err(Problem::NotNames {
                key: key.to_string(),
                seg: seg.to_string(),
            });
        }
        path.push(Step::Key(name.to_string()));
        while !rest.is_empty() {
            let (idx, after) = rest.split_once(']').ok_or_else(|| Problem::Unclosed {
                key: key.to_string(),
                seg: seg.to_string(),
            })?;
            let i = idx.parse::<usize>().map_err(|source| Problem::NotIndex {
                key: key.to_string(),
                idx: idx.to_string(),
                source,
            })?;
            path.push(Step::Index(i));
            rest = after.strip_prefix('[').unwrap_or(after);
            if !after.is_empty() && !after.starts_with('[') {
                return Err(Problem::After {
                    key: key.to_string(),
                    after: after.to_string(),
                });
            }
        }
    }
    Ok(path)
}

fn parse_value(text: &str) -> Result<Value, Problem> {
    if text.is_empty() {
        return Err(Problem::Empty);
    }
    match format!("v = {text}").parse::<Table>() {
        // `v = X` parsed is a table of one key, `v`.
        Ok(mut t) => t.remove("v").ok_or(Problem::Empty),
        Err(source) => {
            let (text, source) = (text.to_string(), Box::new(source));
            let word = text
                .chars()
                .all(|c| c.is_ascii_alphanumeric() || "-_./".contains(c));
            if numeric(&text) {
                // A number TOML cannot hold is no string: `samples=99999999999999999999`
                // read as one was refused as "expected u64", naming no range.
                let digits = text.trim_start_matches(['+', '-']);
                if digits.chars().all(|c| c.is_ascii_digit() || c == '_') {
                    Err(Problem::OutOfRange { text })
                } else {
                    Err(Problem::NotNumber { text, source })
                }
            } else if word {
                Ok(Value::String(text))
            } else {
                Err(Problem::NotToml { text, source })
            }
        }
    }
}

/// True if `text` is written as a number is (a sign, a digit first, then only what a
/// number holds): TOML refusing it means the number is wrong, not that it is a word.
fn numeric(text: &str) -> bool {
    let body = text.strip_prefix(['+', '-']).unwrap_or(text);
    body.starts_with(|c: char| c.is_ascii_digit())
        && body
            .chars()
            .all(|c| c.is_ascii_digit() || "_.eE+-".contains(c))
}

/// The scenario text `text` with every set applied in order; the result still has to
/// be read as a scenario (which checks keys and values).
pub fn apply(text: &str, sets: &[Set]) -> Result<String, SetError> {
    if sets.is_empty() {
        return Ok(text.to_string());
    }
    let keys: Vec<String> = sets.iter().map(Set::key).collect();
    if let Some((a, b)) = twins(&keys) {
        return Err(SetError::Twice(sets[a].text.clone(), sets[b].text.clone()));
    }
    let mut table: Table = text.parse().map_err(|e| SetError::NotToml(Box::new(e)))?;
    for s in sets {
        put(&mut table, &s.path, s.value.clone()).map_err(|source| SetError::Put {
            text: s.text.clone(),
            source,
        })?;
    }
    Ok(toml::to_string(&table)?)
}

/// The first two of `keys` that say one time in two units at one place
/// (`network.forward.delay` and `network.forward.delay_ms`), by index, earlier first.
/// A `--set` replaces the file's twin, so two such sets would silently keep the
/// last: `tactile run` and `tactile sweep` refuse them.
pub fn twins(keys: &[String]) -> Option<(usize, usize)> {
    fn split(k: &str) -> (&str, &str) {
        let k = k.trim();
        k.rsplit_once('.').unwrap_or(("", k))
    }
    (0..keys.len()).find_map(|b| {
        let (pb, kb) = split(&keys[b]);
        keys[..b]
            .iter()
            .position(|a| {
                let (pa, ka) = split(a);
                pa == pb && crate::units::twin(ka) == Some(kb)
            })
            .map(|a| (a, b))
    })
}

/// The message for two `--set`s of one time in two units.
pub fn twice(a: &str, b: &str) -> String {
    format!("--set {a} and --set {b} give one time in two units: give it once, in milliseconds (_ms) or in samples")
}

/// Puts `value` at `path` in `table`, making the tables on the way that do not exist.
fn put(table: &mut Table, path: &[Step], value: Value) -> Result<(), Problem> {
    let Some((Step::Key(first), rest)) = path.split_first() else {
        return Err(Problem::NoKey);
    };
    if rest.is_empty() {
        // A time given in one unit replaces the file's in the other (`delay_ms` the
        // file's `delay`): both would be refused, and the --set is the newer word.
        // Two sets of one time are refused before (`twins`), so only the file's
        // twin is ever removed here.
        if let Some(twin) = crate::units::twin(first) {
            table.remove(twin);
        }
        table.insert(first.clone(), value);
        return Ok(());
    }
    let slot = table.entry(first.clone()).or_insert_with(|| match rest[0] {
        Step::Key(_) => Value::Table(Table::new()),
        Step::Index(_) => Value::Array(Vec::new()),
    });
    put_in(slot, first, rest, value)
}

fn put_in(slot: &mut Value, name: &str, rest: &[Step], value: Value) -> Result<(), Problem> {
    match (&rest[0], slot) {
        (Step::Key(_), Value::Table(t)) => put(t, rest, value),
        (Step::Index(i), Value::Array(a)) => {
            let len = a.len();
            let item = a.get_mut(*i).ok_or_else(|| Problem::NoEntry {
                name: name.to_string(),
                i: *i,
                len,
            })?;
            if rest.len() == 1 {
                *item = value;
                Ok(())
            } else {
                put_in(item, &format!("{name}[{i}]"), &rest[1..], value)
            }
        }
        (Step::Key(k), _) => Err(Problem::NotTable {
            name: name.to_string(),
            key: k.clone(),
        }),
        (Step::Index(i), _) => Err(Problem::NotArray {
            name: name.to_string(),
            i: *i,
        }),
    }
}

/// Splits a sweep's list of values at the commas outside brackets, braces and quotes:
/// `0,10,50` is three values, `[0,0,0],[5,5,5]` two.
pub fn split_values(list: &str) -> Vec<String> {
    let (mut out, mut cur, mut depth, mut quote) = (Vec::new(), String::new(), 0i32, None);
    for c in list.chars() {
        match (c, quote) {
            ('"' | '\'', None) => quote = Some(c),
            (q, Some(open)) if q == open => quote = None,
            ('[' | '{', None) => depth += 1,
            (']' | '}', None) => depth -= 1,
            (',', None) if depth == 0 => {
                out.push(cur.trim().to_string());
                cur.clear();
                continue;
            }
            _ => {}
        }
        cur.push(c);
    }
    out.push(cur.trim().to_string());
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    const BASE: &str = "name = \"t\"\nrate_hz = 100.0\n\n[network.forward]\ndelay = [0, 0, 0]\n\n[[objects]]\nstiffness = [1.0, 2.0]\n";

    /// The cause stays under the set's error: the set's text above, TOML's or the
    /// integer parser's reason below, each reached through `source()`.
    #[test]
    fn a_bad_set_keeps_its_cause() {
        use std::error::Error as _;
        let e = Set::parse("objects[x]=1").expect_err("no index");
        let problem = e.source().expect("the problem");
        assert!(matches!(
            problem.downcast_ref::<Problem>(),
            Some(Problem::NotIndex { .. })
        ));
        let int = problem.source().expect("the integer's reason");
        assert!(int.downcast_ref::<std::num::ParseIntError>().is_some());
        let e = Set::parse("rate_hz=[1,").expect_err("not TOML");
        let toml = e.source().and_then(|p| p.source()).expect("TOML's reason");
        assert!(toml.is::<Box<toml::de::Error>>(), "{toml:?}");
        let e = apply("= nope", &[set("rate_hz=1")]).expect_err("not TOML");
        assert!(e.source().is_some_and(|c| c.is::<Box<toml::de::Error>>()));
    }

    fn set(s: &str) -> Set {
        Set::parse(s).expect("parse")
    }

    fn read(text: &str) -> Table {
        text.parse().expect("toml")
    }

    #[test]
    fn values_replace_and_tables_are_made() {
        let t = read(
            &apply(
                BASE,
                &[
                    set("rate_hz=1000.0"),
                    set("network.forward.delay = [5, 5, 5]"),
                    set("network.backward.delay=[1,2,3]"),
                    set("mode=lockstep"),
                    set("objects[0].stiffness[1]=600.0"),
                ],
            )
            .expect("apply"),
        );
        assert_eq!(t["rate_hz"].as_float(), Some(1000.0));
        assert_eq!(t["mode"].as_str(), Some("lockstep"));
        assert_eq!(
            t["network"]["forward"]["delay"],
            Value::Array(vec![5.into(), 5.into(), 5.into()])
        );
        assert_eq!(t["network"]["backward"]["delay"][2].as_integer(), Some(3));
        assert_eq!(t["objects"][0]["stiffness"][1].as_float(), Some(600.0));
    }

    #[test]
    fn bad_sets_say_what_is_wrong() {
        for (s, needle) in [
            ("rate_hz", "expected KEY=VALUE"),
            ("rate_hz=", "no value"),
            ("a..b=1", "dotted path"),
            ("rate_hz=[1,", "not a TOML value"),
            ("objects[x]=1", "not an index"),
            ("samples=99999999999999999999", "out of range"),
            ("seed=-99999999999999999999", "out of range"),
            ("rate_hz=1.5.3", "is not a number"),
        ] {
            let e = Set::parse(s).expect_err(s).to_string();
            assert!(e.contains(needle), "{s}: {e}");
        }
        for (s, needle) in [
            ("rate_hz.x=1", "rate_hz is not a table"),
            ("objects[3].stiffness=1", "objects has 1 entries"),
            ("name[0]=1", "name is not an array"),
        ] {
            let e = apply(BASE, &[set(s)]).expect_err(s).to_string();
            assert!(e.contains(needle) && e.contains(s), "{s}: {e}");
        }
    }

    /// A number beyond i64 was read as a string, so the scenario said "expected u64"
    /// and no range; a word that merely starts with a digit stays a string.
    #[test]
    fn numbers_toml_cannot_hold_are_refused_and_words_stay_strings() {
        let e = Set::parse("samples=99999999999999999999")
            .expect_err("beyond i64")
            .to_string();
        assert!(
            e.contains("samples=99999999999999999999") && e.contains("9223372036854775807"),
            "{e}"
        );
        assert_eq!(set("name=2024run").value, Value::String("2024run".into()));
        assert_eq!(
            set("seed=9223372036854775807").value,
            Value::Integer(i64::MAX)
        );
    }

    #[test]
    fn lists_split_outside_brackets_and_quotes() {
        assert_eq!(split_values("0,10, 50"), ["0", "10", "50"]);
        assert_eq!(split_values("[0,0,0],[5,5,5]"), ["[0,0,0]", "[5,5,5]"]);
        assert_eq!(split_values("\"a,b\",c"), ["\"a,b\"", "c"]);
        assert_eq!(split_values("none"), ["none"]);
    }
}
