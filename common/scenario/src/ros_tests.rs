//! The ROS 2 tables' unit tests (beside the module, which they would double).
use super::*;
use crate::{RobotCommand, RosRobotConfig, Scenario};

#[test]
fn a_trajectory_command_needs_an_arm_from_its_urdf() {
    let e = RobotCommand::Trajectory
        .validate(false)
        .expect_err("no arm");
    assert!(e.to_string().contains("slave.ros2.command"), "{e}");
    assert!(RobotCommand::Trajectory.validate(true).is_ok());
    let e = RobotCommand::Pose.validate(false).expect_err("no arm");
    assert!(e.to_string().contains("\"pose\" needs [slave.arm]"), "{e}");
    assert!(RobotCommand::Pose.validate(true).is_ok());
    let cfg: RosRobotConfig = toml::from_str("command = \"pose\"").expect("toml");
    assert_eq!(cfg.command, RobotCommand::Pose);
    assert!(RobotCommand::Positions.validate(false).is_ok());
    let cfg: RosRobotConfig =
        toml::from_str("command = \"trajectory\"\ntrajectory_time_s = 0.004").expect("toml");
    assert_eq!(
        (cfg.command, cfg.trajectory_time_s),
        (RobotCommand::Trajectory, Some(0.004))
    );
}

#[test]
fn topic_names_follow_ros_rules() {
    assert!(topic_name("/phantom/joint_states", "f").is_ok());
    for bad in ["joint_states", "/", "/a//b", "/1abc", "/a-b", "/a/"] {
        assert!(topic_name(bad, "f").is_err(), "{bad}");
    }
    // rmw's limit, and a long name is quoted short (a megabyte of name was quoted
    // whole).
    let at = |n: usize| format!("/{}", "a".repeat(n - 1));
    assert!(topic_name(&at(super::MAX_TOPIC_CHARS), "f").is_ok());
    let e = topic_name(&at(1_000_000), "f")
        .expect_err("too long")
        .to_string();
    assert!(
        e.contains("1000000 characters, more than the 247") && e.len() < 300,
        "{e}"
    );
}

#[test]
fn a_force_goes_to_the_device_frame_and_back() {
    let m = ForceMapConfig {
        axes: [1, 2, 0],
        sign: [1.0, -1.0, 1.0],
    };
    let f = [1.0, 2.0, 3.0];
    assert_eq!(m.to_device(f), [2.0, -3.0, 1.0]);
    assert_eq!(m.to_paper(m.to_device(f)), f);
    let bad = ForceMapConfig {
        axes: [0, 0, 2],
        ..ForceMapConfig::default()
    };
    assert!(bad.validate("m").is_err());
}

#[test]
fn a_ros2_device_runs_in_real_time_only() {
    let mut sc = crate::Scenario::default();
    sc.slave.backend = Backend::Ros2;
    assert!(sc.validate().is_ok());
    sc.mode = crate::Mode::Lockstep;
    let e = sc.validate().expect_err("lockstep");
    assert!(e.to_string().contains("field `mode`"), "{e}");
}

#[test]
fn joint_names_must_differ() {
    let mut d = RosDeviceConfig::default();
    d.joints[2] = "waist".into();
    let e = d.validate().expect_err("duplicate");
    assert!(e.to_string().contains("master.ros2.joints[2]"), "{e}");
}

/// A device's gimbal URDF is an input like an arm's: made absolute against the
/// scenario's folder (never the run's output folder) and listed for the run's
/// `inputs/` (issue 51: it was left out, and `tactile run` read it from `--out`).
#[test]
fn a_gimbal_urdf_is_an_input_resolved_against_the_scenarios_folder() {
    let text = "[master]\nbackend = \"ros2\"\n[master.ros2]\n\
                gimbal = { urdf = \"../devices/omni.urdf\", base = \"base\", tip = \"stylus\" }\n";
    let sc: crate::Scenario = toml::from_str(text).expect("scenario");
    assert_eq!(sc.input_paths(), vec!["../devices/omni.urdf".to_string()]);
    let r = sc.resolved(std::path::Path::new("/lab/scenarios"));
    let g = r.master.ros2.gimbal.as_ref().expect("gimbal");
    assert_eq!(g.urdf, "/lab/scenarios/../devices/omni.urdf");
    let back = r.relative_to(std::path::Path::new("/lab/scenarios/.."));
    let g = back.master.ros2.gimbal.as_ref().expect("gimbal");
    assert_eq!(g.urdf, "devices/omni.urdf");
}

/// A 6-joint arm over ROS 2, `[slave.arm]` and `[slave.ros2]` with `extra` in it.
fn arm_over_ros(extra: &str) -> String {
    format!(
        "[slave]\nbackend = \"ros2\"\n[slave.ros2]\ncommand = \"trajectory\"\n{extra}\n\
         [slave.arm]\nurdf = \"ur5.urdf\"\nbase = \"base_link\"\ntip = \"tool0\"\n\
         home = [0.0, -1.2, 1.6, -1.97, -1.5708, 0.0]\nkp = [1.0, 1.0, 1.0, 1.0, 1.0, 1.0]\n\
         kd = [0.1, 0.1, 0.1, 0.1, 0.1, 0.1]\n"
    )
}

/// The paper arm's three-element keys beside `[slave.arm]` are refused by name even
/// when their value is the default (issue 52: a default value passed unnoticed), and
/// the error says what to write instead.
#[test]
fn a_paper_arm_key_beside_an_arm_is_refused_by_name_at_any_value() {
    Scenario::from_toml_str(&arm_over_ros("")).expect("[slave.arm] alone");
    let cases = [
        (
            "joints = [\"joint1\", \"joint2\", \"joint3\"]",
            "joints",
            "delete `joints`",
        ),
        (
            "max_velocity = [2.0, 2.0, 2.0]",
            "max_velocity",
            "<limit velocity>",
        ),
        ("map = { unit = \"rad\" }", "map", "delete [slave.ros2.map]"),
        (
            "wrench_map = { axes = [0, 1, 2] }",
            "wrench_map",
            "frame_id",
        ),
    ];
    for (extra, field, instead) in cases {
        let e = Scenario::from_toml_str(&arm_over_ros(extra)).expect_err(field);
        let text = e.to_string();
        assert!(
            text.starts_with(&format!(
                "field `slave.ros2.{field}`: is for the paper's 3-DoF arm only"
            )),
            "{text}"
        );
        assert!(text.contains(instead), "{text}");
    }
    // Six names for a UR5's six joints: told what to write, not that it takes three.
    let six = "joints = [\"a\", \"b\", \"c\", \"d\", \"e\", \"f\"]";
    let e = Scenario::from_toml_str(&arm_over_ros(six)).expect_err("six names");
    assert!(e.to_string().contains("delete `joints`"), "{e}");
    // Whatever the backend: with an arm the keys never apply.
    let simulated =
        arm_over_ros("max_velocity = [1.0, 1.0, 1.0]").replace("\"ros2\"", "\"simulated\"");
    let e = Scenario::from_toml_str(&simulated).expect_err("simulated");
    assert!(e.to_string().contains("slave.ros2.max_velocity"), "{e}");
}

/// The paper's arm keeps its keys: given ones are used and written back, absent ones
/// take the paper arm's defaults and are not written.
#[test]
fn the_paper_arm_keeps_its_three_joint_keys() {
    let text = "[slave]\nbackend = \"ros2\"\n[slave.ros2]\njoints = [\"a\", \"b\", \"c\"]\n\
                max_velocity = [1.0, 2.0, 3.0]\n";
    let sc = Scenario::from_toml_str(text).expect("paper arm");
    let r = &sc.slave.ros2;
    assert_eq!(r.paper_joints(), ["a", "b", "c"].map(String::from));
    assert_eq!(r.paper_max_velocity(), [1.0, 2.0, 3.0]);
    assert_eq!(Scenario::from_toml_str(&sc.to_toml()).expect("again"), sc);
    let d = RosRobotConfig::default();
    assert_eq!(
        d.paper_joints(),
        ["joint1", "joint2", "joint3"].map(String::from)
    );
    assert_eq!(d.paper_max_velocity(), [crate::PAPER_MAX_VELOCITY; 3]);
    let written: toml::Table = Scenario::default().to_toml().parse().expect("toml");
    let slave_ros2 = &written["slave"]["ros2"];
    for key in ["joints", "map", "max_velocity", "wrench_map"] {
        assert!(slave_ros2.get(key).is_none(), "{key} written: {slave_ros2}");
    }
}

/// A record of an arm made before issue 52 holds the paper arm's four keys at their
/// defaults (every key was written): it still reads, as the same scenario without
/// them, while a scenario file with them, or a record with another value, is refused.
#[test]
fn an_old_record_of_an_arm_reads_without_the_paper_arms_defaults() {
    let old = "joints = [\"joint1\", \"joint2\", \"joint3\"]\n\
               max_velocity = [2.0, 2.0, 2.0]\n\
               map = { sign = [1.0, 1.0, 1.0], offset = [0.0, 0.0, 0.0], unit = \"rad\", \
               min = [-3.141592653589793, -3.141592653589793, -3.141592653589793], \
               max = [3.141592653589793, 3.141592653589793, 3.141592653589793], \
               elbow_after_shoulder = false }\n\
               wrench_map = { axes = [0, 1, 2], sign = [1.0, 1.0, 1.0] }";
    let want = Scenario::from_toml_str(&arm_over_ros("")).expect("arm alone");
    assert!(Scenario::from_toml_str(&arm_over_ros(old)).is_err());
    let read = Scenario::from_recorded_toml(&arm_over_ros(old)).expect("old record");
    assert_eq!(read, want);
    let other = arm_over_ros("max_velocity = [1.0, 2.0, 2.0]");
    let e = Scenario::from_recorded_toml(&other).expect_err("not what was written");
    assert!(e.to_string().contains("slave.ros2.max_velocity"), "{e}");
    // The paper's arm keeps whatever it recorded.
    let paper = "[slave]\nbackend = \"ros2\"\n[slave.ros2]\nmax_velocity = [2.0, 2.0, 2.0]\n";
    let read = Scenario::from_recorded_toml(paper).expect("paper");
    assert_eq!(read.slave.ros2.max_velocity, Some([2.0; 3]));
}

/// A paper-arm key beside `[slave.arm]` is refused by name whatever its shape, and
/// whether or not the scenario has an `_ms` key (review of issue 52, 1 and 4).
#[test]
fn a_paper_arm_key_is_refused_by_name_before_its_type_is_read() {
    let e = Scenario::from_toml_str(&arm_over_ros("max_velocity = 2.0")).expect_err("2.0");
    assert!(e.to_string().contains("slave.ros2.max_velocity"), "{e}");
    assert!(e.to_string().contains("paper's 3-DoF arm only"), "{e}");
    let six = "joints = [\"a\", \"b\", \"c\", \"d\", \"e\", \"f\"]";
    let with_ms = format!("{}[network.forward]\ndelay_ms = 100\n", arm_over_ros(six));
    let e = Scenario::from_toml_str(&with_ms).expect_err("six names");
    assert!(e.to_string().contains("delete `joints`"), "{e}");
}

/// A recorded arm whose backend is not ROS 2 never used the paper arm's ROS keys:
/// all four are dropped whatever their value (review of issue 52, 5).
#[test]
fn a_recorded_simulated_arm_drops_the_paper_arms_ros_keys() {
    let simulated = |extra: &str| arm_over_ros(extra).replace("\"ros2\"", "\"simulated\"");
    let want = Scenario::from_toml_str(&simulated("")).expect("arm alone");
    let old = simulated(
        "max_velocity = [1.0, 2.0, 2.0]\njoints = [\"a\", \"b\", \"c\"]\n\
         wrench_map = { axes = [2, 1, 0] }\nmap = { unit = \"deg\" }",
    );
    let read = Scenario::from_recorded_toml(&old).expect("old simulated record");
    assert_eq!(read, want);
    assert!(Scenario::from_toml_str(&old).is_err());
}
