//! What a scenario that cannot run says: the dotted path of the field and the
//! problem, and the small range checks every table shares.

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
        return Err(invalid(field, format!("{v} must be finite and {want}")));
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
                format!("{x} must be {want}"),
            ));
        }
    }
    Ok(())
}

/// A TOML error as one line: `line L, column C: message`.
pub fn one_line(text: &str, e: &toml::de::Error) -> String {
    let msg = e.message().split_whitespace().collect::<Vec<_>>().join(" ");
    match e.span() {
        Some(span) => {
            let before = &text[..span.start.min(text.len())];
            let line = before.matches('\n').count() + 1;
            let column = before.len() - before.rfind('\n').map_or(0, |i| i + 1) + 1;
            format!("line {line}, column {column}: {msg}")
        }
        None => msg,
    }
}
