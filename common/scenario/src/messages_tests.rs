//! How a refused scenario is worded, read as a user gets it (the scenario's text, a
//! `--set`): each message names its field and shows its numbers short. Apart from
//! the modules they test, which `overrides` itself depends on.

use crate::overrides::{apply, Set};
use crate::Scenario;
/// serde's messages about a type or a length named no field: `schedule = [[0, 5]]`
/// said `line 3, column 13: invalid length 2, expected an array of length 4`, and
/// through `--set` (whose line and column are dropped) not even where.
#[test]
fn every_type_error_of_a_scenario_names_its_field() {
    for (text, field) in [
        (
            "[network.forward]\nschedule = [[0, 5]]\n",
            "network.forward.schedule[0]",
        ),
        (
            "[network.forward]\ndelay = [1.5, 1, 1]\n",
            "network.forward.delay[0]",
        ),
        ("samples = \"many\"\n", "samples"),
        ("[control]\nkind = \"mpc\"\n", "control.kind"),
        // An object's kind picks its fields (serde reads a tagged table whole, so
        // the place is the object's).
        (
            "[[environment.objects]]\nkind = \"plane\"\npoint = [0, 0]\n",
            "environment.objects[0]",
        ),
        (
            "[[environment.objects]]\nkind = \"cone\"\n",
            "environment.objects[0].kind",
        ),
        (
            "[[environment.objects]]\nkind = \"plane\"\n",
            "environment.objects[0]",
        ),
        (
            "[network.forward]\njitter = { jitter = \"x\" }\n",
            "network.forward.jitter.jitter",
        ),
        ("[network.forward]\ndelya = 1\n", "network.forward.delya"),
    ] {
        let e = Scenario::from_toml_str(text).expect_err(text).to_string();
        assert!(e.contains(&format!("field `{field}`")), "{text}: {e}");
    }
    for set in [
        "network.forward.schedule=[[0,5]]",
        "network.forward.delay=[1.5,1,1]",
    ] {
        let text = apply("", &[Set::parse(set).expect("set")]).expect("applied");
        let e = Scenario::from_toml_str(&text).expect_err(set).to_string();
        let field = set.split_once('=').map(|(k, _)| k).unwrap_or_default();
        assert!(e.contains(&format!("field `{field}")), "{set}: {e}");
    }
}

#[test]
fn a_name_longer_than_a_label_is_refused() {
    let name = |n: usize| format!("name = \"{}\"\n", "é".repeat(n));
    Scenario::from_toml_str(&name(crate::MAX_NAME_CHARS)).expect("256 characters");
    let e = Scenario::from_toml_str(&name(1_000_000)).expect_err("a million");
    assert_eq!(
        e.to_string(),
        "field `name`: is 1000000 characters long, more than the 256 a name may have"
    );
}

/// `--set rate_hz=1e300` was refused with the rate's 301 digits: every range
/// check shows its value short (`crate::shown::Num`).
#[test]
fn a_huge_value_is_shown_short_by_every_check() {
    for set in [
        "rate_hz=1e300",
        "master.device.step_s=1e300",
        "master.clutch_spring=1e300",
        "slave.dynamics.step_s=1e300",
        "operator={kind=\"circle\",center=[0,0,0],radius=1e300,period_s=1}",
        "master.ros2.watch.timeout_ms=1e-300",
    ] {
        let text = apply("", &[Set::parse(set).expect("set")]).expect("applied");
        let e = Scenario::from_toml_str(&text).expect_err(set).to_string();
        assert!(e.len() < 200, "{set}: {e}");
        assert!(e.contains("e300") || e.contains("e-300"), "{set}: {e}");
    }
}
