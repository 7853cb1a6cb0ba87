//! A scenario a run can record. Every node's record starts with the scenario as run
//! (`Start::scenario_toml`, beside its name): one frame, at most
//! [`MAX_FRAME`](tactile_records::MAX_FRAME) bytes. A scenario whose start entry is
//! longer passed `check` and failed at the run's first write ("a record of 2003010
//! bytes is longer than a frame may be"), leaving an 8-byte `master.rec` and no
//! summary. So the start entry is measured before anything starts, as the recorder
//! encodes it ([`tactile_records::body_len`]), with what the scenario does not decide
//! at its widest: the host's name, the clock domain, the prefix, the link's and the
//! scheduling's words, and every input path as long as a path may be (a run reads
//! its copies in its output folder's `inputs/`, wherever that is).

use crate::error::Error;
use std::path::Path;
use tactile_records::{Sched, Start};
use tactile_scenario::Scenario;

/// Linux's longest host name (`HOST_NAME_MAX`).
const HOST_NAME_MAX: usize = 64;
/// The longest path Linux resolves (`PATH_MAX`).
const PATH_MAX: usize = 4096;
/// Room for the clock domain (a boot id is 36 characters; `TACTILE_CLOCK_DOMAIN`
/// as set here, if longer).
const CLOCK_ROOM: usize = 64;
/// Room for the link's description (a node given Zenoh endpoints by hand lists
/// them; a longer list is refused by that node's own recorder as it starts).
const LINK_ROOM: usize = 1024;
/// Room for the scheduling's words (its policy, and why it is not as asked).
const SCHED_ROOM: usize = 1024;

/// The start entry of `scenario`'s runs at its widest: as a node writes it, with the
/// fields the scenario does not decide as long as they can be.
fn widest_start(scenario: &Scenario, base_dir: &Path) -> Start {
    let mut s = scenario.resolved(base_dir);
    for path in s.input_paths_mut() {
        *path = "/".repeat(PATH_MAX);
    }
    let clock = tactile_runtime::start::clock_domain();
    Start {
        role: "emulator".into(),
        version: env!("CARGO_PKG_VERSION").into(),
        pid: u32::MAX,
        host: "h".repeat(HOST_NAME_MAX),
        clock: "c".repeat(clock.len().max(CLOCK_ROOM)),
        prefix: "p".repeat(tactile_runtime::lock::MAX_PREFIX_LEN),
        link: "l".repeat(LINK_ROOM),
        scenario: s.name.clone(),
        scenario_toml: s.to_toml(),
        samples: u64::MAX,
        rate_hz: s.rate_hz,
        sched: Sched {
            policy: "s".repeat(SCHED_ROOM),
            priority: u8::MAX,
            cpu: Some(usize::MAX),
            wake_early_us: u64::MAX,
            poll_us: u64::MAX,
            memory_locked: true,
            idle_poll: true,
            note: Some("n".repeat(SCHED_ROOM)),
        },
        unix_ms: u64::MAX,
        mono_ns: u64::MAX,
    }
}

/// Refuses (bad input, naming the field that takes the most) a scenario whose runs'
/// records could not start: its start entry longer than a frame.
pub fn check(scenario: &Scenario, base_dir: &Path) -> Result<(), Error> {
    let start = widest_start(scenario, base_dir);
    let entry = tactile_records::Record::<(), ()>::Start(start);
    let len = tactile_records::body_len(&entry)
        .map_err(|e| Error::Failed(format!("measuring the scenario's record: {e}")))?;
    let Err(e) = tactile_records::fits(len) else {
        return Ok(());
    };
    let (field, bytes) = largest(scenario);
    Err(Error::BadInput(format!(
        "field `{field}`: the scenario is too large to record: each node's record starts with the scenario as run, and that entry would take up to {len} bytes where a record's frame holds {} ({e}); `{field}` takes {bytes} bytes of it",
        tactile_records::MAX_FRAME
    )))
}

/// The field of `scenario` whose TOML is longest, and its length: a table's longest
/// part, down to a value (`name`, `environment.changes`, `network.forward.schedule`).
fn largest(scenario: &Scenario) -> (String, usize) {
    let Ok(mut value) = toml::Value::try_from(scenario) else {
        return ("name".into(), scenario.name.len());
    };
    let mut field = String::new();
    let mut bytes = 0;
    while let toml::Value::Table(t) = value {
        let Some((k, v, n)) = t
            .into_iter()
            .map(|(k, v)| {
                let n = v.to_string().len();
                (k, v, n)
            })
            .max_by_key(|(_, _, n)| *n)
        else {
            break;
        };
        field = if field.is_empty() {
            k
        } else {
            format!("{field}.{k}")
        };
        bytes = n;
        value = v;
    }
    (field, bytes)
}

#[cfg(test)]
mod tests {
    use super::*;
    use tactile_scenario::{Change, Object};

    /// A scenario that fits within a frame's bytes by a few is refused all the same
    /// when its runs' start entries, with the node's own words at their widest,
    /// would not; and the field named is the one that takes the room.
    #[test]
    fn a_scenario_too_large_to_record_is_refused_naming_its_largest_field() {
        let mut s = Scenario::paper();
        s.name = "x".repeat(300_000);
        check(&s, Path::new("/")).expect("300 kB of name fits a frame");
        s.name = "x".repeat(600_000);
        let e = check(&s, Path::new("/")).expect_err("twice 600 kB does not");
        assert!(matches!(e, Error::BadInput(_)), "{e}");
        assert!(e.to_string().starts_with("field `name`:"), "{e}");
        let mut s = Scenario::paper();
        s.environment.objects.push(Object::Sphere {
            center: [0.0; 3],
            radius: 0.01,
            stiffness: [1.0; 3],
        });
        s.environment.changes = vec![
            Change {
                at_s: 1.0,
                object: 1,
                move_by: [0.0; 3],
                stiffness: None,
            };
            20_000
        ];
        let e = check(&s, Path::new("/")).expect_err("20,000 changes");
        assert!(
            e.to_string().starts_with("field `environment.changes`:"),
            "{e}"
        );
    }
}
