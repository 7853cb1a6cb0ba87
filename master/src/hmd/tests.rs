//! The master's simulated hand (beside [`super`], which they would double; a real
//! device's tests are in `hmd_device_tests.rs`): every hand mode starts the operator's
//! motion at home and blends onto it, unless the motion starts there.
use super::*;
use crate::operator::Target;
use tactile_scenario::Operator;

/// The targets of the first `samples` with `operator` and `hand`, at 1 kHz.
fn targets(operator: Operator, hand: HandMode, samples: u64) -> Vec<[f64; 3]> {
    let mut sc = Scenario::paper();
    sc.rate_hz = 1000.0;
    sc.operator = operator;
    sc.master.hand.mode = hand;
    let source = OperatorSource::load(&sc.operator, std::path::Path::new(".")).expect("op");
    let mut m = Master::new(&sc, source).expect("master");
    let (mut f, mut sent) = (Forward::default(), Sent::default());
    (0..samples)
        .map(|n| {
            m.forward(n, 0, Input::Simulated, (&mut f, &mut sent));
            sent.target
        })
        .collect()
}

fn home() -> [f64; 3] {
    let lengths = tactile_math::geometry::Geometry::PAPER.lengths();
    tactile_math::kernels::fk(&lengths, &tactile_math::arith::StdTrig, [0.0; 3])
}

#[test]
fn every_hand_starts_a_circle_at_home_and_blends_onto_it() {
    let circle = Operator::Circle {
        center: [0.0, -0.107, -0.065],
        radius: 0.02,
        period_s: 2.0,
        plane: "xz".into(),
    };
    let source = OperatorSource::load(&circle, std::path::Path::new(".")).expect("op");
    for hand in [HandMode::Position, HandMode::Impedance] {
        let t = targets(circle.clone(), hand, 1500);
        assert_eq!(t[0], home(), "{hand:?}");
        // Without the blend the first sample jumped 36 mm; along it no sample
        // steps more than a tenth of a millimetre.
        let step = t
            .windows(2)
            .map(|w| tactile_math::vec3::norm([0, 1, 2].map(|i| w[1][i] - w[0][i])));
        let largest = step.fold(0.0, f64::max);
        assert!(largest < 1e-4, "{hand:?}: {largest} m");
        // After the approach (1 s), the circle itself.
        let Target::Position(p) = source.target(1200, 1e-3) else {
            panic!("a position")
        };
        let off = tactile_math::vec3::norm([0, 1, 2].map(|i| t[1200][i] - p[i]));
        assert!(off < 1e-15, "{hand:?}: {off} m off the circle");
    }
}

#[test]
fn a_trajectory_that_starts_at_home_is_not_blended() {
    // The paper's path starts with the joints at zero: its targets are exactly
    // the path's, under either hand.
    for hand in [HandMode::Position, HandMode::Impedance] {
        let t = targets(Operator::Paper, hand, 600);
        let truth = Engine::new(
            tactile_math::arith::ArithKind::F64,
            tactile_math::geometry::Geometry::PAPER,
            tactile_scenario::CordicSettings::default()
                .config()
                .expect("cordic"),
        )
        .expect("engine");
        for (n, a) in t.iter().enumerate() {
            let want = truth.fk(tactile_math::validation::paper_joint_path(n as f64 * 1e-3));
            assert_eq!(*a, want, "{hand:?} at sample {n}");
        }
    }
}
