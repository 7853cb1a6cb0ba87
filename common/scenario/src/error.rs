//! What a scenario that cannot run says: the dotted path of the field and the
//! problem, and the small range checks every table shares.

use crate::shown::Num;
use thiserror::Error;

/// A scenario that cannot run, with the dotted path of the offending field.
#[derive(Debug, Error, PartialEq)]
pub enum ScenarioError {
    /// TOML syntax, an unknown key or a wrong type (the message names the key).
    #[error("{0}")]
    Parse(String),
    /// A value out of range.
    #[error("field `{field}`: {problem}")]
    Invalid {
        /// Dotted path of the field, e.g. `network.forward.delay`.
        field: String,
        /// What is wrong.
        problem: String,
    },
}

pub(crate) fn invalid(field: impl Into<String>, problem: impl Into<String>) -> ScenarioError {
    ScenarioError::Invalid {
        field: field.into(),
        problem: problem.into(),
    }
}

pub(crate) fn positive(v: f64, field: &str, zero_ok: bool) -> Result<(), ScenarioError> {
    if !v.is_finite() || v < 0.0 || (!zero_ok && v == 0.0) {
        let want = if zero_ok { "non-negative" } else { "positive" };
        return Err(invalid(
            field,
            format!("{} must be finite and {want}", Num(v)),
        ));
    }
    Ok(())
}

pub(crate) fn finite3(v: &[f64; 3], field: &str) -> Result<(), ScenarioError> {
    for (i, x) in v.iter().enumerate() {
        if !x.is_finite() {
            return Err(invalid(
                format!("{field}[{i}]"),
                format!("{x} is not a finite number"),
            ));
        }
    }
    Ok(())
}

pub(crate) fn positive3(v: &[f64; 3], field: &str, allow_zero: bool) -> Result<(), ScenarioError> {
    finite3(v, field)?;
    for (i, x) in v.iter().enumerate() {
        if *x < 0.0 || (!allow_zero && *x == 0.0) {
            let want = if allow_zero {
                "non-negative"
            } else {
                "positive"
            };
            return Err(invalid(
                format!("{field}[{i}]"),
                format!("{} must be {want}", Num(*x)),
            ));
        }
    }
    Ok(())
}

/// A TOML error as one line: `line L, column C: field `PATH`: message`, the field's
/// dotted path where the error's place is in one (serde's own messages, such as
/// `invalid length 2, expected an array of length 4`, do not say which field).
pub fn one_line(text: &str, e: &toml::de::Error) -> String {
    let msg = e.message().split_whitespace().collect::<Vec<_>>().join(" ");
    match e.span() {
        Some(span) => {
            let before = &text[..span.start.min(text.len())];
            let line = before.matches('\n').count() + 1;
            let column = before.len() - before.rfind('\n').map_or(0, |i| i + 1) + 1;
            match crate::path::field_at(text, span.start) {
                Some(f) => format!("line {line}, column {column}: field `{f}`: {msg}"),
                None => format!("line {line}, column {column}: {msg}"),
            }
        }
        None => msg,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The shared checks most fields go through show a huge value short: `{}` of
    /// -1e308 is 309 digits.
    #[test]
    fn a_huge_value_given_to_the_shared_checks_is_shown_short() {
        let e = format!("{:?}", positive(-1e308, "x", true));
        assert!(e.contains("-1e308 must be"), "{e}");
        assert!(e.len() < 120, "{e}");
        let e = format!("{:?}", positive3(&[1.0, -1e308, 1.0], "v", true));
        assert!(e.contains("-1e308 must be"), "{e}");
        assert!(e.len() < 120, "{e}");
    }
}
