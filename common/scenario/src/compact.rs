//! A scenario's TOML with its extreme numbers written short: `toml` writes a float
//! in plain digits, so `timeout_ms = 1e300` came back from `tactile check` (and into
//! a run's `scenario.toml`) as 301 digits. A float whose plain form is longer than
//! [`LONGEST`] characters is written in its shortest exact form instead (`1e300`,
//! what messages show: [`crate::shown::Num`]); every other number keeps the plain
//! form it always had, so the TOML of every ordinary scenario is unchanged, byte for
//! byte.

use crate::shown::Num;
use toml_edit::visit_mut::VisitMut;
use toml_edit::{DocumentMut, Formatted, Value};

/// Characters a float is written in at most before its short form is used (the
/// plain form of any f64 from 1e-5 to 1e16 is shorter).
pub const LONGEST: usize = 24;

/// `text` (TOML as `toml` writes it) with every float longer than [`LONGEST`]
/// written short; `text` itself where there is none.
pub(crate) fn floats(text: &str) -> String {
    let Ok(mut doc) = text.parse::<DocumentMut>() else {
        return text.to_string();
    };
    let mut c = Compact { changed: false };
    c.visit_document_mut(&mut doc);
    if c.changed {
        doc.to_string()
    } else {
        text.to_string()
    }
}

struct Compact {
    changed: bool,
}

impl VisitMut for Compact {
    fn visit_float_mut(&mut self, node: &mut Formatted<f64>) {
        if node.display_repr().len() <= LONGEST {
            return;
        }
        if let Ok(Value::Float(mut short)) = Num(*node.value()).to_string().parse::<Value>() {
            *short.decor_mut() = node.decor().clone();
            *node = short;
            self.changed = true;
        }
    }
}

#[cfg(test)]
mod tests {
    use crate::overrides::{apply, Set};
    use crate::Scenario;

    #[test]
    fn an_extreme_number_is_written_short_and_reads_back_the_same() {
        let text = apply(
            "",
            &[
                Set::parse("master.ros2.watch.timeout_ms=1e300").expect("set"),
                Set::parse("slave.predictor.measurement_noise=1e-30").expect("set"),
            ],
        )
        .expect("applied");
        let s = Scenario::from_toml_str(&text).expect("valid");
        let toml = s.to_toml();
        assert!(toml.contains("timeout_ms = 1e300\n"), "{toml}");
        assert!(toml.contains("measurement_noise = 1e-30\n"), "{toml}");
        assert!(toml.lines().all(|l| l.len() < 80), "{toml}");
        assert_eq!(Scenario::from_toml_str(&toml).expect("reads back"), s);
        // An ordinary scenario's TOML is what `toml` writes, byte for byte.
        let paper = Scenario::paper();
        assert_eq!(paper.to_toml(), toml::to_string(&paper).expect("toml"));
    }
}
