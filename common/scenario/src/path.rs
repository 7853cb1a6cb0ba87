//! The dotted path of the field at a place in a TOML text: serde's errors about a
//! value's type or length (`invalid length 2, expected an array of length 4`) say
//! what is wrong but not where, and a line and column point into a text a `--set` or
//! an `_ms` conversion wrote, not the user's. The TOML is read again with its spans
//! (only when there is an error to word), and the innermost key, value or table at
//! the error's place named as the scenario's own checks name fields:
//! `network.forward.schedule[0]`, `environment.objects[1].stiffness`.

use std::ops::Range;
use toml_edit::{ImDocument, Item, Table, Value};

/// The field at byte `at` of `text`, if `text` is TOML and something is there.
pub(crate) fn field_at(text: &str, at: usize) -> Option<String> {
    let doc = ImDocument::parse(text).ok()?;
    in_table(doc.as_table(), at, "")
}

fn join(prefix: &str, key: &str) -> String {
    if prefix.is_empty() {
        key.to_string()
    } else {
        format!("{prefix}.{key}")
    }
}

fn holds(span: Option<Range<usize>>, at: usize) -> bool {
    span.is_some_and(|s| s.contains(&at))
}

/// The innermost field of `t` at `at` (a value's, or a key's own span).
fn in_table(t: &Table, at: usize, prefix: &str) -> Option<String> {
    t.iter().find_map(|(k, item)| {
        let field = join(prefix, k);
        in_item(item, at, &field)
            .or_else(|| holds(t.key(k).and_then(|key| key.span()), at).then_some(field))
    })
}

fn in_item(item: &Item, at: usize, field: &str) -> Option<String> {
    let whole = |t: &Table, f: String| in_table(t, at, &f).or(holds(t.span(), at).then_some(f));
    match item {
        Item::Value(v) => in_value(v, at, field),
        Item::Table(t) => whole(t, field.to_string()),
        Item::ArrayOfTables(a) => a
            .iter()
            .enumerate()
            .find_map(|(i, t)| whole(t, format!("{field}[{i}]"))),
        Item::None => None,
    }
}

fn in_value(v: &Value, at: usize, field: &str) -> Option<String> {
    if !holds(v.span(), at) {
        return None;
    }
    let inner = match v {
        Value::Array(a) => a
            .iter()
            .enumerate()
            .find_map(|(i, x)| in_value(x, at, &format!("{field}[{i}]"))),
        Value::InlineTable(t) => t.iter().find_map(|(k, x)| {
            let f = join(field, k);
            in_value(x, at, &f)
                .or_else(|| holds(t.key(k).and_then(|key| key.span()), at).then_some(f))
        }),
        _ => None,
    };
    Some(inner.unwrap_or_else(|| field.to_string()))
}

#[cfg(test)]
mod tests {
    use super::field_at;

    fn at(text: &str, needle: &str) -> Option<String> {
        field_at(text, text.find(needle).expect("needle"))
    }

    #[test]
    fn values_keys_tables_and_elements_are_named() {
        let t = "name = \"x\"\n[network.forward]\nschedule = [[0, 5], [9, 1, 2, 3]]\ndelay = [1.5, 1, 1]\nj = { jitter = 2, c = [1] }\n\n[[environment.objects]]\nkind = \"plane\"\n[[environment.objects]]\nkind = \"sphere\"\nbad = 1\n";
        assert_eq!(
            at(t, "[0, 5]").as_deref(),
            Some("network.forward.schedule[0]")
        );
        assert_eq!(
            at(t, "1, 2, 3]").as_deref(),
            Some("network.forward.schedule[1][1]")
        );
        assert_eq!(at(t, "1.5").as_deref(), Some("network.forward.delay[0]"));
        assert_eq!(at(t, "delay").as_deref(), Some("network.forward.delay"));
        assert_eq!(at(t, "2, c").as_deref(), Some("network.forward.j.jitter"));
        assert_eq!(at(t, "[1] }").as_deref(), Some("network.forward.j.c"));
        assert_eq!(at(t, "1] }").as_deref(), Some("network.forward.j.c[0]"));
        assert_eq!(
            at(t, "\"sphere\"").as_deref(),
            Some("environment.objects[1].kind")
        );
        assert_eq!(at(t, "bad").as_deref(), Some("environment.objects[1].bad"));
        assert_eq!(at(t, "\"x\"").as_deref(), Some("name"));
        assert_eq!(field_at("a = [", 4), None, "not TOML");
    }
}
