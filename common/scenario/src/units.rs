//! Time in time units: `delay_ms`, `schedule_ms` and a jitter's `jitter_ms`, the
//! milliseconds forms of a channel's `delay`, `schedule` and `jitter.jitter` (which
//! count samples). A user who means 100 ms should not have to know that it is 10
//! samples at 100 Hz and 100 at 1 kHz.
//!
//! They are converted once, on the scenario's TOML as read and before it is typed, into
//! the sample forms: the emulator, the records and a run's `scenario.toml` see samples
//! only, so a run given `delay_ms` is the run given the equivalent `delay`, bit for
//! bit. A channel delays by whole samples, so a delay (or a schedule's start) that is
//! not a whole number of samples at the scenario's rate is refused, naming the field,
//! the value and the two nearest that are (rounding would make two swept values the
//! same run without a word). A jitter's spread is fractional in samples already.

use crate::error::{invalid, one_line, ScenarioError};
use crate::network::ChannelConfig;
use crate::network::MAX_DELAY_SAMPLES;
use crate::shown::{listed, Num};
use crate::Scenario;
use toml::{Table, Value};

/// The keys that say one quantity in two units, samples then milliseconds: giving
/// both is an error, and a `--set` of one replaces the other.
pub const TWINS: [(&str, &str); 3] = [
    ("delay", "delay_ms"),
    ("schedule", "schedule_ms"),
    ("jitter", "jitter_ms"),
];

/// The other unit's key of a time key (`delay` for `delay_ms` and back).
pub fn twin(key: &str) -> Option<&'static str> {
    TWINS.iter().find_map(|&(samples, ms)| match key {
        k if k == samples => Some(ms),
        k if k == ms => Some(samples),
        _ => None,
    })
}

/// How far from a whole number a sample count may be and still be it (floating
/// point: 0.1 ms at 10 kHz is 1.0000000000000002 samples).
const WHOLE: f64 = 1e-6;

/// The largest jitter spread accepted, samples (as `JitterConfig::validate`).
const MAX_JITTER_SAMPLES: f64 = 10_000.0;

/// The largest schedule start accepted in ms, samples: the sample form's start has
/// no cap of its own, and up to 2^53 an f64 counts whole samples exactly.
const MAX_START_SAMPLES: i64 = 1 << 53;

/// How far a time in ms may be from a whole sample and still be it: `check` shows ms
/// rounded to the microsecond.
const HALF_MICROSECOND: f64 = 0.0005 * (1.0 + 1e-9);

/// Rewrites every `_ms` key of `[network.forward]` and `[network.backward]` into its
/// sample form in `doc`, at the scenario's `rate_hz`; true if it changed anything.
pub(crate) fn to_samples(doc: &mut Value) -> Result<bool, ScenarioError> {
    let Ok(rate) = doc.get("rate_hz").map_or(Ok(100.0), rate_of) else {
        // A rate that is no number is refused by the typed parse, naming rate_hz.
        return Ok(false);
    };
    // The rate's own error first: a conversion at an absurd rate would blame the delay.
    crate::validate::check_rate(rate)?;
    let mut changed = false;
    let Some(network) = doc.get_mut("network").and_then(Value::as_table_mut) else {
        return Ok(false);
    };
    for dir in ["forward", "backward"] {
        if let Some(c) = network.get_mut(dir).and_then(Value::as_table_mut) {
            let at = Rate {
                hz: rate,
                field: format!("network.{dir}"),
            };
            changed |= at.channel(c)?;
        }
    }
    Ok(changed)
}

fn rate_of(v: &Value) -> Result<f64, ()> {
    match v {
        Value::Float(x) => Ok(*x),
        Value::Integer(i) => Ok(*i as f64),
        _ => Err(()),
    }
}

/// One channel's conversion: the rate and the channel's dotted path, for messages.
struct Rate {
    hz: f64,
    field: String,
}

impl Rate {
    fn channel(&self, c: &mut Table) -> Result<bool, ScenarioError> {
        let mut changed = false;
        if let Some(v) = self.take(c, "delay", "delay_ms")? {
            let f = format!("{}.delay_ms", self.field);
            let d = self.axes(&v, &f)?;
            c.insert("delay".into(), Value::Array(d.map(Value::Integer).to_vec()));
            changed = true;
        }
        if let Some(v) = self.take(c, "schedule", "schedule_ms")? {
            let rows = self.schedule(&v, &format!("{}.schedule_ms", self.field))?;
            c.insert("schedule".into(), Value::Array(rows));
            changed = true;
        }
        if let Some(j) = c.get_mut("jitter").and_then(Value::as_table_mut) {
            let at = Rate {
                hz: self.hz,
                field: format!("{}.jitter", self.field),
            };
            if let Some(v) = at.take(j, "jitter", "jitter_ms")? {
                let f = format!("{}.jitter_ms", at.field);
                j.insert("jitter".into(), Value::Float(at.spread(&v, &f)?));
                changed = true;
            }
        }
        Ok(changed)
    }

    /// Removes and returns `ms` from `t`; an error if `samples` is there too.
    fn take(&self, t: &mut Table, samples: &str, ms: &str) -> Result<Option<Value>, ScenarioError> {
        if t.contains_key(ms) && t.contains_key(samples) {
            let f = &self.field;
            return Err(invalid(
                format!("{f}.{ms}"),
                format!("and `{f}.{samples}` are both set: give it once, in milliseconds ({ms}) or in samples ({samples})"),
            ));
        }
        Ok(t.remove(ms))
    }

    /// A milliseconds value as a number, non-negative and finite.
    fn ms(&self, v: &Value, field: &str) -> Result<f64, ScenarioError> {
        let x = rate_of(v).map_err(|_| invalid(field, "is not a number of milliseconds"))?;
        if !x.is_finite() || x < 0.0 {
            return Err(invalid(
                field,
                format!("{} ms must be finite and non-negative", Num(x)),
            ));
        }
        Ok(x)
    }

    /// A delay or a start in milliseconds as whole samples, at most `limit` (a
    /// delay's [`MAX_DELAY_SAMPLES`], a start's [`MAX_START_SAMPLES`]). A value within
    /// half a microsecond of a whole sample is that sample: `check` shows times to
    /// the microsecond (one sample at 300 Hz is 3.333 ms), and what it shows reads
    /// back; two values that close cannot mean two different runs.
    fn samples(&self, v: &Value, field: &str, limit: i64) -> Result<i64, ScenarioError> {
        let ms = self.ms(v, field)?;
        let n = ms * self.hz / 1000.0;
        if n > limit as f64 {
            return Err(invalid(
                field,
                format!(
                    "{} ms is {} samples at {} Hz, beyond {limit}",
                    units_ms(ms),
                    count(n),
                    Num(self.hz)
                ),
            ));
        }
        let step = 1000.0 / self.hz;
        let whole = n.round();
        if (n - whole).abs() > WHOLE && (ms - whole * step).abs() > HALF_MICROSECOND {
            let (lo, hi) = (n.floor() * step, n.ceil() * step);
            return Err(invalid(
                field,
                format!(
                    "{} ms is {} samples at {} Hz; a channel delays by whole samples ({} ms each): give {} or {} ms, or the time in samples (a whole number of samples works at any rate)",
                    units_ms(ms), count(n), Num(self.hz), units_ms(step), units_ms(lo), units_ms(hi)
                ),
            ));
        }
        Ok(whole as i64)
    }

    /// One number for the three axes, or three.
    fn axes(&self, v: &Value, field: &str) -> Result<[i64; 3], ScenarioError> {
        match v {
            Value::Array(a) if a.len() == 3 => {
                let mut d = [0; 3];
                for (i, x) in a.iter().enumerate() {
                    d[i] = self.samples(x, &format!("{field}[{i}]"), MAX_DELAY_SAMPLES)?;
                }
                Ok(d)
            }
            Value::Array(a) => Err(invalid(
                field,
                format!(
                    "has {} elements; it takes one number (every axis) or three (x, y, z)",
                    a.len()
                ),
            )),
            x => Ok([self.samples(x, field, MAX_DELAY_SAMPLES)?; 3]),
        }
    }

    /// Rows `[from_ms, d]` or `[from_ms, dx, dy, dz]` as `[from_sample, dx, dy, dz]`,
    /// the starts strictly increasing.
    fn schedule(&self, v: &Value, field: &str) -> Result<Vec<Value>, ScenarioError> {
        let rows = v.as_array().ok_or_else(|| {
            invalid(
                field,
                "is not an array of rows [from_ms, d] or [from_ms, dx, dy, dz]",
            )
        })?;
        let mut out = Vec::with_capacity(rows.len());
        let mut last = -1;
        for (k, row) in rows.iter().enumerate() {
            let f = format!("{field}[{k}]");
            let r = match row.as_array().map(Vec::as_slice) {
                Some([from, d]) => [from, d, d, d],
                Some([from, dx, dy, dz]) => [from, dx, dy, dz],
                _ => return Err(invalid(f, "a row is [from_ms, d] or [from_ms, dx, dy, dz]")),
            };
            let from = self.samples(r[0], &format!("{f}[0]"), MAX_START_SAMPLES)?;
            if from <= last {
                return Err(invalid(
                    f,
                    "from_ms must be strictly increasing (in whole samples)",
                ));
            }
            last = from;
            let one = row.as_array().is_some_and(|a| a.len() == 2);
            let mut e = vec![Value::Integer(from)];
            for (i, d) in r[1..].iter().enumerate() {
                let at = if one { 1 } else { i + 1 };
                e.push(Value::Integer(self.samples(
                    d,
                    &format!("{f}[{at}]"),
                    MAX_DELAY_SAMPLES,
                )?));
            }
            out.push(Value::Array(e));
        }
        Ok(out)
    }

    /// A jitter's spread in milliseconds as samples (fractional, as `jitter` takes it).
    fn spread(&self, v: &Value, field: &str) -> Result<f64, ScenarioError> {
        let ms = self.ms(v, field)?;
        let n = ms * self.hz / 1000.0;
        if n > MAX_JITTER_SAMPLES {
            return Err(invalid(
                field,
                format!(
                    "{} ms is {} samples at {} Hz, beyond {}",
                    units_ms(ms),
                    count(n),
                    Num(self.hz),
                    Num(MAX_JITTER_SAMPLES)
                ),
            ));
        }
        Ok(n)
    }
}

/// The scenario whose `_ms` keys `converted` holds in samples, read the way a file
/// without them is (`toml::from_str` on its text), so the same mistakes get the same
/// messages: an over-long array is trimmed here and named by `lengths::check`, where
/// `Value::try_into` would refuse it without a field. The converted text's positions
/// are not the user's: where the text as written fails the same way, its line and
/// column are shown, else the field the mistake is in.
pub(crate) fn parse_converted(text: &str, converted: &Value) -> Result<Scenario, ScenarioError> {
    let again = toml::to_string(converted).map_err(|e| {
        ScenarioError::Parse(format!(
            "writing the scenario with its _ms keys in samples: {e}"
        ))
    })?;
    toml::from_str(&again).map_err(|e: toml::de::Error| {
        ScenarioError::Parse(match toml::from_str::<Scenario>(text) {
            Err(as_written) if as_written.message() == e.message() => one_line(text, &as_written),
            _ => field_of(&again, &e),
        })
    })
}

/// `e`'s message with the dotted path of the field its span is on in `text` (the
/// converted text: its lines and columns are not the user's).
fn field_of(text: &str, e: &toml::de::Error) -> String {
    let msg = e.message().split_whitespace().collect::<Vec<_>>().join(" ");
    match e.span().and_then(|s| crate::path::field_at(text, s.start)) {
        Some(f) => format!("field `{f}`: {msg}"),
        None => msg,
    }
}

/// A number of milliseconds as `check` and the messages show it: to the
/// microsecond, shortest form (one sample at 300 Hz is 3.333 ms, not
/// 3.3333333333333335).
fn ms(x: f64) -> Num {
    Num((x * 1000.0).round() / 1000.0)
}

/// A time in ms as a message shows it: as [`ms`] unless that would show a small
/// non-zero value as 0 (a user's 1e-7 ms is shown as they wrote it).
fn units_ms(x: f64) -> Num {
    match ms(x) {
        Num(0.0) if x != 0.0 => Num(x),
        m => m,
    }
}

/// A sample count as a message shows it: to a thousandth of a sample (11 ms at
/// 100 Hz is 1.1 samples, not 1.1000000000000003).
fn count(n: f64) -> Num {
    match Num((n * 1000.0).round() / 1000.0) {
        Num(0.0) if n != 0.0 => Num(n),
        c => c,
    }
}

/// One channel's times in both units, for `tactile check`: `network.forward: delay
/// 10 samples (100 ms at 100 Hz)`, then its jitter and schedule if any (the first
/// rows of a long schedule, and how many more).
pub fn describe(name: &str, c: &ChannelConfig, rate_hz: f64) -> String {
    let per = 1000.0 / rate_hz;
    let both = |d: &[i64], at: &str| match d {
        [x, rest @ ..] if rest.iter().all(|y| y == x) => {
            format!("{x} samples ({} ms{at})", ms(*x as f64 * per))
        }
        _ => {
            let m: Vec<String> = d.iter().map(|x| ms(*x as f64 * per).to_string()).collect();
            format!("{d:?} samples ([{}] ms{at})", m.join(", "))
        }
    };
    let at = format!(" at {} Hz", Num(rate_hz));
    let from = |what: &str| {
        format!(
            "network.{name}: delay per packet from {what} (samples, 1 = {} ms{at})",
            ms(per)
        )
    };
    let mut s = match (&c.replay, &c.delay_histogram, &c.link) {
        (Some(r), _, _) => from(&r.path),
        (None, Some(h), _) => from(&format!(
            "the histogram {}, correlation {}",
            h.path.as_deref().or(h.name.as_deref()).unwrap_or_default(),
            Num(h.correlation)
        )),
        (None, None, Some(l)) => link_line(name, l),
        (None, None, None) => format!("network.{name}: delay {}", both(&c.delay, &at)),
    };
    if let Some(j) = &c.jitter {
        let dist = toml::Value::try_from(j.distribution).map_or_else(
            |_| String::new(),
            |v| v.as_str().unwrap_or_default().to_string(),
        );
        s.push_str(&format!(
            "; jitter {} samples ({} ms), {dist}, correlation {}",
            Num(j.jitter),
            ms(j.jitter * per),
            Num(j.correlation)
        ));
    }
    if !c.schedule.is_empty() {
        let rows = c.schedule.iter().map(|e| {
            format!(
                "from sample {} ({} ms) delay {}",
                e[0],
                ms(e[0] as f64 * per),
                both(&e[1..], "")
            )
        });
        s.push_str(&format!("; schedule {}", listed(rows)));
    }
    s
}

#[cfg(test)]
#[path = "units_tests.rs"]
mod tests;

/// A link's line: its server, its queue and its packets' size on the wire.
fn link_line(name: &str, l: &crate::LinkConfig) -> String {
    let server = match (&l.path, l.rate, &l.rate_trace) {
        (_, Some(r), _) => format!("{} bit/s", Num(r)),
        (_, None, Some(f)) => format!("the rates over time in {f}"),
        (Some(p), None, None) => format!("the Mahimahi trace {p}"),
        (None, None, None) => format!("the shipped trace {}", l.trace.as_deref().unwrap_or("")),
    };
    let queue = toml::Value::try_from(l.queue)
        .ok()
        .and_then(|v| v.as_str().map(str::to_string))
        .unwrap_or_default();
    let mut bound = Vec::new();
    if let Some(p) = l.packets {
        bound.push(format!("packets={p}"));
    }
    if let Some(b) = l.bytes {
        bound.push(format!("bytes={b}"));
    }
    let bound = if bound.is_empty() {
        String::new()
    } else {
        format!(" [{}]", bound.join(", "))
    };
    format!(
        "network.{name}: a link of {server}, queue {queue}{bound}, packets of {} bytes on the wire ({} payload + {} header)",
        l.packet_bytes(),
        l.payload_bytes,
        l.header_bytes
    )
}
