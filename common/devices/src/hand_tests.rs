//! The 6-DoF device's decoding (beside the module, which they would double).
use super::*;
use crate::map::tests::js;
use tactile_ros::msg::Message;
use tactile_scenario::{JointMapConfig, OmniButton};

const OMNI: &str = include_str!("../../../deploy/devices/phantom_omni.urdf");

fn gimbal() -> Gimbal {
    Gimbal::new(OMNI, "base", "stylus", &FrameRotation::default()).expect("gimbal")
}

#[test]
fn a_touchs_joints_give_the_point_and_the_gimbals_orientation() {
    let map = JointMap::new(
        ["waist".into(), "shoulder".into(), "elbow".into()],
        JointMapConfig::default(),
    );
    let names = ["waist", "shoulder", "elbow", "yaw", "pitch", "roll"];
    let q = [0.1, 0.4, -0.2, 4.5, 0.3, 0.7];
    let h = joints_cdr(&map, Some(&gimbal()), &js(&names, &q).to_cdr()).expect("a reading");
    assert_eq!(h.point, [0.1, 0.4, -0.2]);
    let want = quaternion(&gimbal().orientation(&q));
    assert_eq!(h.rotation, Some(want));
    // Without the gimbal's joints the message is refused, not half read.
    let short = js(&names[..4], &q[..4]);
    assert_eq!(
        joints_cdr(&map, Some(&gimbal()), &short.to_cdr()),
        Err(Reject::Missing("pitch".into()))
    );
    let wild = js(&names, &[0.1, 0.4, -0.2, 1e3, 0.3, 0.7]);
    assert!(matches!(
        joints_cdr(&map, Some(&gimbal()), &wild.to_cdr()),
        Err(Reject::OutOfRange { .. })
    ));
    assert_eq!(
        joints_cdr(&map, None, &js(&names, &q).to_cdr()).map(|h| h.rotation),
        Ok(None)
    );
}

#[test]
fn a_pose_is_taken_normalized_and_a_non_rotation_is_refused() {
    let p = |position: [f64; 3], orientation: [f64; 4]| {
        PoseStamped {
            header: Header::at(5, "fd_base"),
            position,
            orientation,
        }
        .to_cdr()
    };
    let h = pose_cdr(&p([0.01, 0.02, 0.03], [0.0, 0.0, 0.6, 0.8000001])).expect("a pose");
    assert_eq!(h.point, [0.01, 0.02, 0.03]);
    let q = h.rotation.expect("turned");
    assert!((q.iter().map(|v| v * v).sum::<f64>() - 1.0).abs() < 1e-15);
    for bad in [
        p([0.0, f64::NAN, 0.0], [0.0, 0.0, 0.0, 1.0]),
        p([0.0, 120.0, 0.0], [0.0, 0.0, 0.0, 1.0]),
        p([0.0; 3], [0.0; 4]),
        p([0.0; 3], [0.0, 0.0, 0.0, f64::INFINITY]),
        p([0.0; 3], [0.5, 0.5, 0.5, 0.6]),
    ] {
        assert!(matches!(pose_cdr(&bad), Err(Reject::BadPose(_))));
    }
    assert!(matches!(pose_cdr(&[0, 1, 0, 0]), Err(Reject::Malformed(_))));
}

#[test]
fn each_clutch_reads_its_own_message() {
    let b = ClutchConfig::Bool { topic: "/c".into() };
    assert_eq!(clutch_cdr(&b, &Bool { data: true }.to_cdr()), Ok(true));
    assert_eq!(clutch_cdr(&b, &Bool { data: false }.to_cdr()), Ok(false));
    let j = ClutchConfig::Joy {
        topic: "/c".into(),
        button: 1,
    };
    let joy = |buttons: Vec<i32>| {
        Joy {
            header: Header::at(1, ""),
            axes: vec![],
            buttons,
        }
        .to_cdr()
    };
    assert_eq!(clutch_cdr(&j, &joy(vec![0, 1])), Ok(true));
    // CRTK's "clicked" (2) has been let go already: released.
    assert_eq!(clutch_cdr(&j, &joy(vec![0, 2])), Ok(false));
    assert_eq!(clutch_cdr(&j, &joy(vec![1, 0])), Ok(false));
    assert_eq!(
        clutch_cdr(&j, &joy(vec![1])),
        Err(Reject::Missing("buttons[1]".into()))
    );
    let ev = |grey, white| {
        OmniButtonEvent {
            grey_button: grey,
            white_button: white,
        }
        .to_cdr()
    };
    for (button, want) in [(OmniButton::Grey, true), (OmniButton::White, false)] {
        let c = ClutchConfig::OmniButton {
            topic: "/phantom/button".into(),
            button,
        };
        assert_eq!(clutch_cdr(&c, &ev(1, 0)), Ok(want));
    }
    assert!(matches!(
        clutch_cdr(&b, &[0, 1, 0, 0]),
        Err(Reject::Malformed(_))
    ));
}

#[test]
fn each_force_message_carries_the_force() {
    let f = [1.5, -0.5, 0.25];
    let w = WrenchStamped::from_cdr(&force_cdr(ForceMessage::Wrench, f, 9, "base")).expect("w");
    assert_eq!(
        (w.force, w.torque, w.header.frame_id.as_str()),
        (f, [0.0; 3], "base")
    );
    let o = OmniFeedback::from_cdr(&force_cdr(ForceMessage::OmniFeedback, f, 9, "")).expect("o");
    assert_eq!(o.force, f);
    let a = Float64MultiArray::from_cdr(&force_cdr(ForceMessage::Float64MultiArray, f, 9, ""))
        .expect("a");
    assert_eq!(a.data, f.to_vec());
    for kind in [
        ForceMessage::Wrench,
        ForceMessage::OmniFeedback,
        ForceMessage::Float64MultiArray,
    ] {
        assert!(
            tactile_ros::rmw::type_hash(force_type(kind)).is_some(),
            "{kind:?}"
        );
    }
}

/// omni_msgs/OmniButtonEvent's buttons are int32, 1 pressed and 0 released: any
/// other value (7, -1, 2^31 as the int32 it wraps to) is dropped, on either button,
/// rather than read as pressed (issue 51).
#[test]
fn a_button_other_than_0_or_1_is_dropped() {
    let ev = |grey, white| {
        OmniButtonEvent {
            grey_button: grey,
            white_button: white,
        }
        .to_cdr()
    };
    let c = ClutchConfig::OmniButton {
        topic: "/phantom/button".into(),
        button: OmniButton::Grey,
    };
    assert_eq!(clutch_cdr(&c, &ev(0, 1)), Ok(false));
    for bad in [7, -1, i32::MIN, 2] {
        assert_eq!(
            clutch_cdr(&c, &ev(bad, 0)),
            Err(Reject::BadButton {
                field: "grey_button",
                value: bad
            })
        );
        let e = clutch_cdr(&c, &ev(1, bad)).expect_err("white");
        assert!(e.to_string().contains("white_button is"), "{e}");
    }
    // Counted as dropped, the clutch keeping its last good state.
    let inbox = crate::watch::Inbox::new();
    inbox.offer(clutch_cdr(&c, &ev(1, 0)), 1);
    inbox.offer(clutch_cdr(&c, &ev(7, 0)), 2);
    assert_eq!(inbox.counts(), (2, 1));
    assert_eq!(inbox.latest().map(|l| (l.value, l.at_ns)), Some((true, 1)));
}

/// A JointState naming a joint twice is dropped, whichever reader takes it: the
/// three joints', the gimbal's, an arm's (issue 51).
#[test]
fn a_joint_named_twice_is_dropped_by_every_reader() {
    let map = JointMap::new(
        ["waist".into(), "shoulder".into(), "elbow".into()],
        JointMapConfig::default(),
    );
    let good = js(&["waist", "shoulder", "elbow"], &[0.0, 0.1, 0.2]).to_cdr();
    assert!(map.angles_cdr(&good).is_ok());
    let twice = js(
        &["waist", "shoulder", "elbow", "waist"],
        &[0.0, 0.1, 0.2, 0.5],
    )
    .to_cdr();
    let dup = Reject::DuplicateJoint("waist".into());
    assert_eq!(map.angles_cdr(&twice), Err(dup.clone()));
    assert_eq!(joints_cdr(&map, None, &twice), Err(dup));
    // Another joint than the three named, repeated: still not a well-defined state.
    let other = js(&["yaw", "waist", "shoulder", "elbow", "yaw"], &[0.0; 5]).to_cdr();
    assert_eq!(
        map.angles_cdr(&other),
        Err(Reject::DuplicateJoint("yaw".into()))
    );
}
