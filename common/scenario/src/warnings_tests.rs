use crate::overrides::{apply, Set};
use crate::Scenario;

/// The warnings of the default scenario with `sets` applied.
fn warnings(sets: &[&str]) -> Vec<String> {
    let sets: Vec<Set> = sets.iter().map(|s| Set::parse(s).expect("set")).collect();
    let text = apply("", &sets).expect("applied");
    Scenario::from_toml_str(&text).expect("valid").warnings()
}

/// The one warning of `sets` holding every needle (and no other warning).
fn one_warning(sets: &[&str], needles: &[&str]) {
    let w = warnings(sets);
    assert_eq!(w.len(), 1, "{sets:?}: {w:#?}");
    for n in needles {
        assert!(w[0].contains(n), "{sets:?}: {n:?} not in {}", w[0]);
    }
}

#[test]
fn the_defaults_and_the_paper_say_nothing() {
    assert_eq!(warnings(&[]), Vec::<String>::new());
    assert_eq!(Scenario::paper().warnings(), Vec::<String>::new());
}

/// `network.forward.corrupt = 1` ran without a word while no valid position ever
/// reached the slave.
#[test]
fn a_channel_that_lets_nothing_through_is_said() {
    one_warning(
        &["network.forward.corrupt=1.0"],
        &[
            "network.forward.corrupt = 1",
            "no valid position reaches the slave",
        ],
    );
    one_warning(
        &["network.backward.loss=1.0"],
        &[
            "network.backward.loss = 1",
            "no valid force reaches the master",
        ],
    );
    one_warning(
        &["network.forward.loss_model={kind=\"gemodel\",p=1.0,r=0.0}"],
        &["network.forward.loss_model (gemodel)"],
    );
    one_warning(
        &["network.forward.loss_model={kind=\"state\",p13=0.01,p31=0.0}"],
        &["network.forward.loss_model (state)", "never left"],
    );
    for passes in [
        "network.forward.corrupt=0.999",
        "network.forward.loss_model={kind=\"gemodel\",p=0.1,r=0.5}",
        "network.forward.loss_model={kind=\"state\",p13=0.01,p31=0.5}",
    ] {
        assert_eq!(warnings(&[passes]), Vec::<String>::new(), "{passes}");
    }
}

/// `[control.mmt]` under another kind, and the same class: a kind's, a mode's or a
/// backend's settings set where another is chosen.
#[test]
fn settings_of_another_kind_are_said_to_be_ignored() {
    one_warning(
        &["control.kind=tdpa", "control.mmt.forgetting=0.99"],
        &[
            "control.mmt.forgetting is set",
            "control.kind = \"mmt\"",
            "\"tdpa\"",
        ],
    );
    assert_eq!(
        warnings(&["control.kind=mmt", "control.mmt.forgetting=0.99"]),
        Vec::<String>::new()
    );
    one_warning(
        &["control.wave_impedance=20.0"],
        &["control.wave_impedance"],
    );
    one_warning(
        &["control.max_damping=300.0"],
        &["control.max_damping", "tdpa"],
    );
    assert_eq!(
        warnings(&[
            "control.kind=mmt",
            "control.mmt.slave=tdpa",
            "control.max_damping=300.0"
        ]),
        Vec::<String>::new()
    );
    one_warning(&["codec.forward.k=0.2"], &["codec.forward.k", "\"none\""]);
    one_warning(
        &["codec.backward.kind=deadband", "codec.backward.v_ref=0.1"],
        &["codec.backward.v_ref", "\"adaptive\""],
    );
    one_warning(
        &[
            "slave.predictor.kind=linear",
            "slave.predictor.process_noise=2.0",
        ],
        &["slave.predictor.process_noise", "\"kalman\""],
    );
    one_warning(
        &["master.hand.mass=0.3", "master.hand.stiffness=300.0"],
        &[
            "master.hand.mass, master.hand.stiffness are set",
            "impedance",
        ],
    );
    one_warning(
        &["master.ros2.ramp_s=1.0"],
        &["master.ros2.ramp_s", "master is simulated"],
    );
    one_warning(
        &["arithmetic=f64", "cordic.frac=12"],
        &["cordic.frac", "\"f64\""],
    );
    one_warning(&["ros.domain_id=3"], &["ros.domain_id", "ROS 2"]);
}

/// A change or a motion after the run's end was not said.
#[test]
fn what_comes_after_the_end_is_said() {
    let wall = "environment.objects=[{kind=\"plane\",point=[0,0,-0.16],normal=[0,0,1],stiffness=[300,300,300]}]";
    let at = |s: f64| format!("environment.changes=[{{at_s={s:?},object=0,move_by=[0,0,0.01]}}]");
    one_warning(
        &["samples=100", wall, &at(1.0)],
        &[
            "environment.changes[0].at_s = 1 s",
            "sample 100",
            "last (99)",
        ],
    );
    assert_eq!(
        warnings(&["samples=100", wall, &at(0.99)]),
        Vec::<String>::new()
    );
    one_warning(
        &[
            "samples=100",
            "operator={kind=\"press\",from=[0,0,0],to=[0,0,0.01],move_s=2.0}",
        ],
        &["operator.move_s = 2 s", "run (1 s)"],
    );
    one_warning(
        &["samples=20", "control.kind=mmt"],
        &["control.mmt.min_contacts = 20", "no model"],
    );
}

/// The same class in `[slave.arm]`: the Cartesian impedance's settings under the joint
/// servo.
#[test]
fn an_arms_cartesian_settings_under_the_joint_servo_are_said_to_be_ignored() {
    let arm = "[slave.arm]\nurdf = \"ur5.urdf\"\nbase = \"base_link\"\ntip = \"tool0\"\n\
               home = [0.0, -1.2, 1.6, -1.97, -1.5708, 0.0]\nkp = [1.0, 1.0, 1.0, 1.0, 1.0, 1.0]\n\
               kd = [0.1, 0.1, 0.1, 0.1, 0.1, 0.1]\n";
    let read = |extra: &str| {
        Scenario::from_toml_str(&format!("{arm}{extra}"))
            .expect("valid")
            .warnings()
    };
    assert_eq!(read(""), Vec::<String>::new());
    let cartesian = "[slave.arm.cartesian]\nnullspace_stiffness = 20.0\n";
    let w = read(cartesian);
    assert!(
        w.len() == 1 && w[0].starts_with("slave.arm.cartesian.nullspace_stiffness is set"),
        "{w:#?}"
    );
    assert_eq!(
        read(&cartesian.replace(
            "[slave.arm.cartesian]",
            "servo = \"cartesian\"\n[slave.arm.cartesian]"
        )),
        Vec::<String>::new()
    );
}
