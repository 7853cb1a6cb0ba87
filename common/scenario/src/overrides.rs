//! `--set KEY=VALUE`: one change to a scenario, from the command line or a sweep.
//!
//! KEY is a dotted path into the scenario's TOML (`network.forward.delay`,
//! `environment.objects[0].stiffness`), VALUE a TOML value (`[0, 0, 0]`, `1000.0`,
//! `"lockstep"`; a bare word such as `lockstep` is taken as a string). The changed
//! text is then read like any scenario file, so an unknown key or a bad value gets the
//! same one-line error naming the field.

use toml::{Table, Value};

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
    pub fn parse(text: &str) -> Result<Set, String> {
        let (key, value) = text
            .split_once('=')
            .ok_or_else(|| format!("--set {text:?}: expected KEY=VALUE"))?;
        Ok(Set {
            path: parse_path(key.trim()).map_err(|e| format!("--set {text:?}: {e}"))?,
            value: parse_value(value.trim()).map_err(|e| format!("--set {text:?}: {e}"))?,
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

fn parse_path(key: &str) -> Result<Vec<Step>, String> {
    let mut path = Vec::new();
    for seg in key.split('.') {
        let (name, mut rest) = seg.split_once('[').map_or((seg, ""), |(n, r)| (n, r));
        let ok = !name.is_empty()
            && name
                .chars()
                .all(|c| c.is_ascii_alphanumeric() || c == '_' || c == '-');
        if !ok {
            return Err(format!(
                "{key:?} is not a dotted path of names (segment {seg:?})"
            ));
        }
        path.push(Step::Key(name.to_string()));
        while !rest.is_empty() {
            let (idx, after) = rest
                .split_once(']')
                .ok_or_else(|| format!("{key:?}: unclosed [ in {seg:?}"))?;
            let i = idx
                .parse::<usize>()
                .map_err(|_| format!("{key:?}: [{idx}] is not an index"))?;
            path.push(Step::Index(i));
            rest = after.strip_prefix('[').unwrap_or(after);
            if !after.is_empty() && !after.starts_with('[') {
                return Err(format!("{key:?}: unexpected {after:?} after ]"));
            }
        }
    }
    Ok(path)
}

fn parse_value(text: &str) -> Result<Value, String> {
    if text.is_empty() {
        return Err("no value after =".into());
    }
    match format!("v = {text}").parse::<Table>() {
        Ok(mut t) => t.remove("v").ok_or_else(|| "no value".to_string()),
        Err(e) => {
            let first = e.message().lines().next().unwrap_or("").to_string();
            let word = text
                .chars()
                .all(|c| c.is_ascii_alphanumeric() || "-_./".contains(c));
            if numeric(text) {
                // A number TOML cannot hold is no string: `samples=99999999999999999999`
                // read as one was refused as "expected u64", naming no range.
                let digits = text.trim_start_matches(['+', '-']);
                if digits.chars().all(|c| c.is_ascii_digit() || c == '_') {
                    Err(format!(
                        "{text} is out of range: a scenario's integers are {} to {}",
                        i64::MIN,
                        i64::MAX
                    ))
                } else {
                    Err(format!("{text:?} is not a number ({first})"))
                }
            } else if word {
                Ok(Value::String(text.to_string()))
            } else {
                Err(format!("{text:?} is not a TOML value ({first})"))
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
pub fn apply(text: &str, sets: &[Set]) -> Result<String, String> {
    if sets.is_empty() {
        return Ok(text.to_string());
    }
    let keys: Vec<String> = sets.iter().map(Set::key).collect();
    if let Some((a, b)) = twins(&keys) {
        return Err(twice(&sets[a].text, &sets[b].text));
    }
    let mut table: Table = text.parse().map_err(|e: toml::de::Error| {
        format!("the scenario is not TOML: {}", e.message().trim_end())
    })?;
    for s in sets {
        put(&mut table, &s.path, s.value.clone()).map_err(|e| format!("--set {}: {e}", s.text))?;
    }
    toml::to_string(&table).map_err(|e| format!("encoding the scenario: {e}"))
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
fn put(table: &mut Table, path: &[Step], value: Value) -> Result<(), String> {
    let Some((Step::Key(first), rest)) = path.split_first() else {
        return Err("the path must start with a key".into());
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

fn put_in(slot: &mut Value, name: &str, rest: &[Step], value: Value) -> Result<(), String> {
    match (&rest[0], slot) {
        (Step::Key(_), Value::Table(t)) => put(t, rest, value),
        (Step::Index(i), Value::Array(a)) => {
            let len = a.len();
            let item = a
                .get_mut(*i)
                .ok_or_else(|| format!("{name}[{i}]: {name} has {len} entries"))?;
            if rest.len() == 1 {
                *item = value;
                Ok(())
            } else {
                put_in(item, &format!("{name}[{i}]"), &rest[1..], value)
            }
        }
        (Step::Key(k), _) => Err(format!("{name} is not a table, so it has no {k}")),
        (Step::Index(i), _) => Err(format!("{name} is not an array, so it has no [{i}]")),
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
            let e = Set::parse(s).expect_err(s);
            assert!(e.contains(needle), "{s}: {e}");
        }
        for (s, needle) in [
            ("rate_hz.x=1", "rate_hz is not a table"),
            ("objects[3].stiffness=1", "objects has 1 entries"),
            ("name[0]=1", "name is not an array"),
        ] {
            let e = apply(BASE, &[set(s)]).expect_err(s);
            assert!(e.contains(needle) && e.contains(s), "{s}: {e}");
        }
    }

    /// A number beyond i64 was read as a string, so the scenario said "expected u64"
    /// and no range; a word that merely starts with a digit stays a string.
    #[test]
    fn numbers_toml_cannot_hold_are_refused_and_words_stay_strings() {
        let e = Set::parse("samples=99999999999999999999").expect_err("beyond i64");
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
