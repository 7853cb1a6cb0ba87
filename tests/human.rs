//! The simulated operator as a person (`[master.human]`, docs/05): a seed now matters
//! (tremor, wander and reaction times drawn from it), the same seed repeats bit for
//! bit in-process and as processes, and a press that stops on contact presses less
//! deep than one that does not.

use crate::util::{self, Sandbox};
use std::path::Path;

const PERSON: &str = "\n[master.human]\ntremor_um = 100.0\ndrift_mm = 1.0\nreaction_ms = 150.0\n";

/// `name` from deploy/scenarios, with `extra` appended and `seed`, written into `sb`
/// beside the files it reads.
fn shipped_with(sb: &Sandbox, name: &str, extra: &str, seed: u64) -> std::path::PathBuf {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("../deploy/scenarios");
    let text = std::fs::read_to_string(dir.join(name)).expect("shipped scenario");
    let text = text.replace("seed = 1\n", &format!("seed = {seed}\n"));
    if name == "push-box.toml" {
        let csv = std::fs::read_to_string(dir.join("push-box.csv")).expect("path");
        sb.write("push-box.csv", &csv);
    }
    sb.write(&format!("{seed}-{name}"), &format!("{text}{extra}"))
}

fn signals_of(sb: &Sandbox, out: &str) -> String {
    util::signals(&sb.trace(out))
}

#[test]
fn a_person_repeats_for_a_seed_and_differs_between_seeds() {
    let sb = Sandbox::new("human");
    let one = shipped_with(&sb, "push-box.toml", PERSON, 1);
    let two = shipped_with(&sb, "push-box.toml", PERSON, 2);
    sb.simulate(&one, "a");
    sb.simulate(&one, "b");
    sb.run(&one, "procs");
    sb.simulate(&two, "c");
    let a = signals_of(&sb, "a");
    assert_eq!(a, signals_of(&sb, "b"), "in-process twice");
    assert_eq!(a, signals_of(&sb, "procs"), "processes against in-process");
    assert_ne!(a, signals_of(&sb, "c"), "another seed, another hand");
    let done = |out: &str| util::num(&sb.json(out, "summary.json")["task"]["completion_s"]);
    // Both still push the box home at zero delay, at different times.
    assert_ne!(done("a"), done("c"));
    for out in ["a", "c"] {
        assert!((4.5..5.5).contains(&done(out)), "{out}: {}", done(out));
    }
}

#[test]
fn a_press_that_stops_on_contact_presses_less_deep() {
    let sb = Sandbox::new("human-stop");
    // wall-delay's press over 4 s and without delay: contact comes mid-move.
    let base = |extra: &str, name: &str| {
        let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("../deploy/scenarios");
        let text = std::fs::read_to_string(dir.join("wall-delay.toml"))
            .expect("wall-delay")
            .replace("move_s = 1.0", "move_s = 4.0")
            .replace("delay = [25, 25, 25]", "delay = [0, 0, 0]");
        sb.write(name, &format!("{text}\n{extra}"))
    };
    let plain = base("", "plain.toml");
    let stop = base(
        "[master.human]\nreaction_ms = 150.0\nreaction_sd_ms = 0.0\nresponse = \"stop\"\n",
        "stop.toml",
    );
    sb.simulate(&plain, "plain");
    sb.simulate(&stop, "stop");
    let depth =
        |out: &str| util::num(&sb.json(out, "summary.json")["contact"]["max_penetration_m"]);
    // Measured 4.03 mm against 2.35 mm (docs/05).
    assert!(depth("plain") > 3.5e-3, "plain {}", depth("plain"));
    assert!(
        depth("stop") < 0.7 * depth("plain"),
        "stop {}",
        depth("stop")
    );
}
