//! Every array in a scenario has the length its field takes: serde fills a
//! fixed-size array from the first elements of a longer one and drops the rest, so
//! `delay = [1, 2, 3, 4, 5]` would run as `[1, 2, 3]` and a fourth joint name would
//! vanish. The text as written is compared with the scenario as parsed, written back.

use crate::error::{invalid, ScenarioError};
use toml::Value;

/// The first array in `written` longer or shorter than the same field in `parsed`.
pub(crate) fn check(written: &Value, parsed: &Value) -> Result<(), ScenarioError> {
    walk(written, parsed, "")
}

fn walk(written: &Value, parsed: &Value, at: &str) -> Result<(), ScenarioError> {
    match (written, parsed) {
        (Value::Table(w), Value::Table(p)) => {
            for (k, v) in w {
                if let Some(q) = p.get(k) {
                    let field = if at.is_empty() {
                        k.clone()
                    } else {
                        format!("{at}.{k}")
                    };
                    walk(v, q, &field)?;
                }
            }
            Ok(())
        }
        (Value::Array(w), Value::Array(p)) => {
            if w.len() != p.len() {
                return Err(invalid(
                    at,
                    format!("has {} elements; it takes {}", w.len(), p.len()),
                ));
            }
            for (i, (v, q)) in w.iter().zip(p).enumerate() {
                walk(v, q, &format!("{at}[{i}]"))?;
            }
            Ok(())
        }
        _ => Ok(()),
    }
}

#[cfg(test)]
mod tests {
    use crate::Scenario;

    #[test]
    fn an_array_longer_than_its_field_is_refused_by_name() {
        let e = Scenario::from_toml_str("[network.forward]\ndelay = [1, 2, 3, 4, 5]\n")
            .expect_err("five delays");
        assert_eq!(
            e.to_string(),
            "field `network.forward.delay`: has 5 elements; it takes 3"
        );
        let e = Scenario::from_toml_str("[slave.ros2]\njoints = [\"a\", \"b\", \"c\", \"d\"]\n")
            .expect_err("four joint names");
        assert_eq!(
            e.to_string(),
            "field `slave.ros2.joints`: has 4 elements; it takes 3"
        );
        // A shorter one serde refuses itself, with the line.
        let e = Scenario::from_toml_str("[slave.dynamics]\ninertia = [0.2, 0.2]\n")
            .expect_err("two inertias");
        assert!(
            e.to_string().contains("line 2") && e.to_string().contains("length 2"),
            "{e}"
        );
        Scenario::from_toml_str(&Scenario::paper().to_toml()).expect("the paper round-trips");
    }
}
