//! The ROS 2 tables' unit tests (beside the module, which they would double).
use super::*;

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
