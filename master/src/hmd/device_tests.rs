//! The master with a real 6-DoF device (beside [`super`], which they would double): a
//! pose device's position and every device's orientation measured from its first
//! reading, the clutch onto c(n), and the spring the hand feels while it is released.
use super::*;
use tactile_messages::samples::Signal;

/// A master at 1 kHz with a clutch `spring`, each switch of force at once (the blend
/// is tested apart, in `a_switched_force_ramps_and_a_broken_loop_stops_at_once`).
fn master(spring: f64) -> Master {
    master_ramped(spring, 0.0)
}

fn master_ramped(spring: f64, ramp_s: f64) -> Master {
    let mut sc = Scenario::paper();
    sc.rate_hz = 1000.0;
    sc.master.clutch_spring = spring;
    sc.master.switch_ramp_s = ramp_s;
    let source = OperatorSource::load(&sc.operator, std::path::Path::new(".")).expect("op");
    Master::new(&sc, source).expect("master")
}

/// [`Master::forward`]'s c(n) and record from a device's reading, returned.
fn measured(
    m: &mut Master,
    n: u64,
    now_ns: u64,
    hand: Option<Hand>,
    input: HandInput,
    clutch: Option<bool>,
) -> (Forward, Sent) {
    let (mut f, mut sent) = (Forward::default(), Sent::default());
    let reading = DeviceReading {
        hand,
        kind: input,
        clutch,
    };
    m.forward(n, now_ns, Input::Device(reading), (&mut f, &mut sent));
    (f, sent)
}

fn home() -> [f64; 3] {
    let lengths = tactile_math::geometry::Geometry::PAPER.lengths();
    tactile_math::kernels::fk(&lengths, &tactile_math::arith::StdTrig, [0.0; 3])
}

/// A quarter turn about z, then `deg` more.
fn about_z(deg: f64) -> [f64; 4] {
    let h = deg.to_radians() / 2.0;
    [0.0, 0.0, h.sin(), h.cos()]
}

#[test]
fn a_pose_device_starts_at_home_and_turns_from_its_first_reading() {
    let mut m = master(0.0);
    let first = Hand {
        point: [0.3, -0.1, 0.05],
        rotation: Some(about_z(90.0)),
    };
    let (f, sent) = measured(&mut m, 0, 0, Some(first), HandInput::Pose, None);
    assert_eq!(f.signal.value, home());
    assert_eq!(f.rotation, IDENTITY);
    assert_eq!(
        f.signal.flags & (Flags::POSE | Flags::RELEASED),
        Flags::POSE
    );
    assert_eq!(sent.handle, home());
    let later = Hand {
        point: [0.31, -0.1, 0.03],
        rotation: Some(about_z(120.0)),
    };
    let (f, _) = measured(&mut m, 1, 1, Some(later), HandInput::Pose, None);
    let want = [home()[0] + 0.01, home()[1], home()[2] - 0.02];
    for (got, want) in f.signal.value.iter().zip(want) {
        assert!((got - want).abs() < 1e-15, "{:?}", f.signal.value);
    }
    // 30 degrees about z since the first reading.
    let turn = about_z(30.0);
    for (got, want) in f.rotation.iter().zip(turn) {
        assert!((got - want).abs() < 1e-12, "{:?}", f.rotation);
    }
}

/// The turn since the first reading is about the base's axes (`q q0^-1`): held turned
/// a quarter about x, then turned 30 degrees about the base's z, the master sends 30
/// degrees about z (about the stylus' own axes it would be a turn about y).
#[test]
fn a_turn_is_measured_about_the_bases_axes() {
    let mut m = master(0.0);
    let h = std::f64::consts::FRAC_PI_4.sin();
    let x90 = [h, 0.0, 0.0, h];
    let (s, c) = (15f64.to_radians().sin(), 15f64.to_radians().cos());
    // Rz(30) Rx(90), multiplied out by hand.
    let turned = [c * h, s * h, s * h, c * h];
    let at = |r| Hand {
        point: [0.0; 3],
        rotation: Some(r),
    };
    measured(&mut m, 0, 0, Some(at(x90)), HandInput::Pose, None);
    let (f, _) = measured(&mut m, 1, 1, Some(at(turned)), HandInput::Pose, None);
    for (got, want) in f.rotation.iter().zip(about_z(30.0)) {
        assert!((got - want).abs() < 1e-12, "{:?}", f.rotation);
    }
}

/// Until the device has given a reading the handle is home and unturned, and the first
/// real reading is the origin, not the placeholder.
#[test]
fn no_origin_is_taken_before_the_device_is_read() {
    let mut m = master(0.0);
    let (f, _) = measured(&mut m, 0, 0, None, HandInput::Pose, Some(false));
    assert_eq!(f.signal.value, home());
    assert_eq!(f.rotation, IDENTITY);
    let first = Hand {
        point: [0.3, 0.2, 0.1],
        rotation: Some(about_z(45.0)),
    };
    let (f, _) = measured(&mut m, 1, 1, Some(first), HandInput::Pose, Some(true));
    assert_eq!(f.signal.value, home());
    assert_eq!(f.rotation, IDENTITY);
}

/// A pose device takes the force itself: no joint torques, none clamped.
#[test]
fn a_pose_device_has_no_torques_to_clamp() {
    let mut m = master(0.0);
    measured(&mut m, 0, 0, Some(Hand::default()), HandInput::Pose, None);
    m.backward(&answer(0, [3.0, 3.0, 3.0]));
    assert_eq!(m.tau(), [0.0; 3]);
    assert_eq!(m.counters().torque_clamps, 0);
    assert_eq!(m.felt(), [3.0, 3.0, 3.0]);
}

#[test]
fn a_3dof_device_without_a_clutch_sends_what_it_always_did() {
    let mut m = master(0.0);
    let theta = [0.1, 0.2, 0.3];
    let hand = Hand {
        point: theta,
        rotation: None,
    };
    let (f, sent) = measured(&mut m, 0, 0, Some(hand), HandInput::Joints, None);
    assert!(!f.signal.flags.intersects(Flags::POSE));
    assert_eq!(sent.theta_md, theta);
    let truth = tactile_math::kernels::fk(
        &tactile_math::geometry::Geometry::PAPER.lengths(),
        &tactile_math::arith::StdTrig,
        theta,
    );
    assert_eq!(sent.handle, truth);
}

/// The answer of sample `n` carrying `force`.
fn answer(n: u64, force: [f64; 3]) -> Backward {
    Backward {
        seq: n,
        signal: Signal {
            value: force,
            sent_seq: [n; 3],
            ..Signal::default()
        },
        ..Backward::default()
    }
}

#[test]
fn released_the_hand_feels_the_spring_not_the_robot() {
    for spring in [0.0, 100.0] {
        let mut m = master(spring);
        let at = |x: f64| Hand {
            point: [x, 0.0, 0.0],
            rotation: None,
        };
        measured(&mut m, 0, 0, Some(at(0.0)), HandInput::Pose, Some(true));
        m.backward(&answer(0, [1.0, 0.5, 0.0]));
        assert_eq!(m.felt(), [1.0, 0.5, 0.0], "engaged: the robot's force");
        // Released 2 cm to the right of where it started.
        let (f, sent) = measured(&mut m, 1, 1, Some(at(0.02)), HandInput::Pose, Some(false));
        assert!(f.signal.flags.intersects(Flags::RELEASED));
        assert!(sent.released);
        m.backward(&answer(1, [1.0, 0.5, 0.0]));
        let felt = m.felt();
        assert!(
            (felt[0] + spring * 0.02).abs() < 1e-12,
            "{spring}: {felt:?}"
        );
        assert_eq!([felt[1], felt[2]], [0.0, 0.0]);
        // Engaged again: the robot's force.
        measured(&mut m, 2, 2, Some(at(0.02)), HandInput::Pose, Some(true));
        m.backward(&answer(2, [1.0, 0.5, 0.0]));
        assert_eq!(m.felt(), [1.0, 0.5, 0.0]);
    }
}

/// A release blends the spring in over `switch_ramp_s` from the robot's force felt
/// before it, and an engage the robot's force back; the loop breaking renders zero at
/// once, and its return rises from zero over the same time.
#[test]
fn a_switched_force_ramps_and_a_broken_loop_stops_at_once() {
    let mut m = master_ramped(100.0, 0.01);
    let at = |x: f64| Hand {
        point: [x, 0.0, 0.0],
        rotation: None,
    };
    let robot = [1.0, 0.5, 0.0];
    measured(&mut m, 0, 0, Some(at(0.0)), HandInput::Pose, Some(true));
    m.backward(&answer(0, robot));
    assert_eq!(m.felt(), robot);
    let spring = [-100.0 * 0.02, 0.0, 0.0];
    // Ten samples from `n` with the clutch `engaged`: the felt force goes from `from`
    // to `to` in equal steps.
    let follow = |m: &mut Master, n: &mut u64, engaged: bool, from: [f64; 3], to: [f64; 3]| {
        for k in 1..=10 {
            let n_now = *n;
            measured(
                m,
                n_now,
                n_now,
                Some(at(0.02)),
                HandInput::Pose,
                Some(engaged),
            );
            m.backward(&answer(n_now, robot));
            let a = f64::from(k) / 10.0;
            let want = [0, 1, 2].map(|i| from[i] + a * (to[i] - from[i]));
            let felt = m.felt();
            assert!(
                (0..3).all(|i| (felt[i] - want[i]).abs() < 1e-12),
                "sample {n_now}: {felt:?}, not {want:?}"
            );
            *n += 1;
        }
    };
    let mut n = 1;
    follow(&mut m, &mut n, false, robot, spring);
    follow(&mut m, &mut n, true, spring, robot);
    let timeout = m.peer_timeout;
    for k in 0..timeout {
        measured(
            &mut m,
            n + k,
            n + k,
            Some(at(0.02)),
            HandInput::Pose,
            Some(true),
        );
        m.missing(n + k);
    }
    assert_eq!(m.felt(), [0.0; 3], "the loop broke: nothing rendered");
    n += timeout;
    follow(&mut m, &mut n, true, [0.0; 3], robot);
}

#[test]
fn the_spring_stays_within_the_force_limit() {
    let mut m = master(1000.0);
    let far = Hand {
        point: [0.5, 0.0, 0.0],
        rotation: None,
    };
    measured(
        &mut m,
        0,
        0,
        Some(Hand::default()),
        HandInput::Pose,
        Some(false),
    );
    measured(&mut m, 1, 1, Some(far), HandInput::Pose, Some(false));
    m.backward(&answer(1, [0.0; 3]));
    assert_eq!(m.felt()[0], -3.3);
}

/// c(n) and its record are written whole into the handler's kept slots: reused from
/// sample to sample (a released sample, then engaged ones, a turned hand, then none,
/// joints, then a pose), they hold what fresh slots would, with nothing of the
/// sample before.
#[test]
fn kept_slots_hold_each_sample_as_fresh_ones_would() {
    let (mut kept, mut fresh) = (master(100.0), master(100.0));
    let (mut f, mut sent) = (Forward::default(), Sent::default());
    let turned = Hand {
        point: [0.3, -0.1, 0.05],
        rotation: Some(about_z(30.0)),
    };
    let still = Hand {
        point: [0.31, -0.1, 0.05],
        rotation: None,
    };
    let joints = Hand {
        point: [0.1, 0.2, 0.3],
        rotation: None,
    };
    let steps = [
        (Some(turned), HandInput::Pose, Some(false)),
        (Some(still), HandInput::Pose, Some(true)),
        (Some(still), HandInput::Pose, None),
        (Some(joints), HandInput::Joints, None),
        (None, HandInput::Pose, None),
    ];
    for (n, (hand, input, clutch)) in steps.into_iter().enumerate() {
        let n = n as u64;
        let reading = DeviceReading {
            hand,
            kind: input,
            clutch,
        };
        kept.forward(n, n, Input::Device(reading), (&mut f, &mut sent));
        let want = measured(&mut fresh, n, n, hand, input, clutch);
        assert_eq!((f, sent), want, "sample {n}");
        kept.backward(&answer(n, [0.5, 0.0, 0.0]));
        fresh.backward(&answer(n, [0.5, 0.0, 0.0]));
    }
    assert!(!f.signal.flags.intersects(Flags::RELEASED));
    assert!(!sent.released);
}
