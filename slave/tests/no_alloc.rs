//! A URDF arm's whole slave step allocates nothing once warm (issues 52 and 66): the
//! slave's step on v(n) (the predictor, the control, the IK, the servo and the
//! dynamics over the period, the tool, the contact, h(n)), the record's sample with the
//! arm's joints, the live view's sample, and the steps holding while input is silent.
//! A counting global allocator counts only on the thread that steps the slave, so the
//! test harness's own threads do not disturb the count. One test in this binary, so
//! no other test shares the allocator.

// A global allocator is unsafe by its trait: it only forwards to the system's.
#![allow(unsafe_code)]

use std::alloc::{GlobalAlloc, Layout, System};
use std::cell::Cell;
use std::hint::black_box;
use std::path::Path;
use tactile_messages::samples::{Flags, Forward, Signal};
use tactile_records::slave::SlaveSample;
use tactile_ros::view::SlaveView;
use tactile_scenario::{ArmServo, Scenario};
use tactile_slave::hsd::Slave;
use tactile_slave::peripherals::read_arm;

/// The system's allocator, counting the allocations of a thread that asked for it.
struct Counting;

thread_local! {
    static COUNTING: Cell<bool> = const { Cell::new(false) };
    // Per thread, as the flag: a count shared by the test threads took in another
    // test's allocations when two ran at once.
    static ALLOCATIONS: Cell<u64> = const { Cell::new(0) };
}

fn count() {
    if COUNTING.with(Cell::get) {
        ALLOCATIONS.with(|a| a.set(a.get() + 1));
    }
}

// SAFETY: every call is the system allocator's, with the caller's layout and pointer.
unsafe impl GlobalAlloc for Counting {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        count();
        unsafe { System.alloc(layout) }
    }
    unsafe fn alloc_zeroed(&self, layout: Layout) -> *mut u8 {
        count();
        unsafe { System.alloc_zeroed(layout) }
    }
    unsafe fn realloc(&self, ptr: *mut u8, layout: Layout, new_size: usize) -> *mut u8 {
        count();
        unsafe { System.realloc(ptr, layout, new_size) }
    }
    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        unsafe { System.dealloc(ptr, layout) }
    }
}

#[global_allocator]
static GLOBAL: Counting = Counting;

/// How many allocations `f` makes on this thread.
fn allocations(f: impl FnOnce()) -> u64 {
    let before = ALLOCATIONS.with(Cell::get);
    COUNTING.with(|c| c.set(true));
    f();
    COUNTING.with(|c| c.set(false));
    ALLOCATIONS.with(Cell::get) - before
}

/// The paper master's home, where the operator of `panda.toml` starts.
const HOME: [f64; 3] = [0.0, -0.107, -0.035];

/// The shipped Panda scenario (4 integration steps a sample, a wall 4.5 cm below the
/// home) with its arm under `servo`, as the slave node makes it.
fn panda(servo: ArmServo) -> Slave {
    shipped("panda.toml", servo)
}

/// The shipped scenario `file` with its arm under `servo`, as the slave node makes it.
fn shipped(file: &str, servo: ArmServo) -> Slave {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("../deploy/scenarios");
    let text = std::fs::read_to_string(dir.join(file)).expect("the scenario");
    let mut scenario = Scenario::from_toml_str(&text).expect("the scenario");
    if let Some(arm) = scenario.slave.arm.as_mut() {
        arm.servo = servo;
    }
    let arm = read_arm(&scenario, &dir).expect("the panda");
    let world = tactile_slave::world::SlaveWorld::of_scenario(&scenario, &dir).expect("the world");
    Slave::new(&scenario, arm, world).expect("the slave")
}

/// v(n) of a 6-DoF master pressing down at 0.15 m/s into the wall and turning about
/// the vertical, its clutch released for samples 200 to 219 (the references hold, and
/// the engage after captures the offsets).
fn forward(n: u64) -> Forward {
    let t = n as f64 * 1e-3;
    let turn = 0.2 * t;
    let mut flags = Flags::POSE;
    if (200..220).contains(&n) {
        flags |= Flags::RELEASED;
    }
    Forward {
        seq: n,
        signal: Signal {
            value: [HOME[0], HOME[1], HOME[2] - 0.15 * t.min(0.4)],
            sent_seq: [n; 3],
            origin_seq: [n; 3],
            flags,
            ..Signal::default()
        },
        rotation: [0.0, 0.0, (turn / 2.0).sin(), (turn / 2.0).cos()],
        ..Forward::default()
    }
}

/// One sample as the slave's handler takes it: the step on v(n) and its record with
/// the arm's joints, and the live view's sample.
fn step(slave: &mut Slave, n: u64) -> f64 {
    let mut h = None;
    let step = slave.step(&forward(n), &mut h);
    let torque = h.as_ref().map_or([0.0; 3], |h| h.torque);
    let joints = slave.arm().joints(torque, slave.rotation());
    let view = slave.arm().live(SlaveView {
        theta: joints.q.to_array3(),
        velocity: None,
        torque: joints.tau.to_array3(),
        tool: step.tool,
        force: step.force,
    });
    let tool = step.tool[2];
    let record = SlaveSample::Step(step, joints, slave.world_sample());
    black_box((&record, &view));
    tool + view.arm.map_or(f64::NAN, |a| a.q[0])
}

/// One sample of holding while input is silent, and its record.
fn hold(slave: &mut Slave) -> f64 {
    let held = slave.hold(None);
    let joints = slave.arm().joints([0.0; 3], slave.rotation());
    let record = SlaveSample::Hold(held, joints, slave.world_sample());
    black_box(&record);
    held.tool[2]
}

/// Allocations in 400 samples of the whole step (IK included: the target moves and
/// turns every sample, the clutch is released and engaged again) and 100 of holding,
/// after a warm-up of 10 samples.
fn allocations_in_500_samples(servo: ArmServo) -> u64 {
    let mut slave = panda(servo);
    for n in 0..10 {
        step(&mut slave, n);
    }
    let mut seen = 0.0;
    let count = allocations(|| {
        for n in 10..410 {
            seen += step(&mut slave, n);
        }
        for _ in 0..100 {
            seen += hold(&mut slave);
        }
    });
    let c = slave.counters();
    assert!(seen.is_finite(), "{seen}");
    assert_eq!(c.dynamics_failed, 0);
    assert!(c.contact_steps > 0, "the tool met the wall: {c:?}");
    assert!(c.held_steps == 100 && c.steps == 410, "{c:?}");
    count
}

/// Issues 52 and 66: a URDF arm's whole slave step allocates nothing once warm,
/// under either servo (the Cartesian servo's products, nalgebra's through
/// `matrixmultiply`, which allocated 3 times an integration step, now go through
/// `tactile_chain::matmul::mul_to`).
#[test]
fn the_arms_whole_step_allocates_nothing_once_warm() {
    for servo in [ArmServo::Joint, ArmServo::Cartesian] {
        let n = allocations_in_500_samples(servo);
        assert_eq!(n, 0, "{servo:?} servo: {n} allocations in 500 samples");
    }
}

/// Issue 67: a physics world's state in the slave's record (the moving bodies' poses,
/// the tool body, the task) is inline and bounded: taking it and making the step's
/// record allocate nothing, every sample of a push. (The engine's own step is counted
/// apart and printed: rapier allocates in it.)
#[test]
fn a_physics_worlds_record_allocates_nothing() {
    let mut slave = shipped("panda-push-box.toml", ArmServo::Joint);
    let (mut in_step, mut in_record) = (0, 0);
    for n in 0..500 {
        let mut h = None;
        let mut step = None;
        in_step += allocations(|| step = Some(slave.step(&forward(n), &mut h)));
        let step = step.expect("stepped");
        let joints = slave.arm().joints([0.0; 3], slave.rotation());
        in_record += allocations(|| {
            let record = SlaveSample::Step(step, joints, slave.world_sample());
            black_box(&record);
        });
    }
    let world = slave.world_sample().expect("a physics world");
    assert_eq!(
        (world.bodies, world.first_body),
        (1, 0),
        "the box, every sample"
    );
    assert!(world.task.is_some());
    assert_eq!(
        in_record, 0,
        "{in_record} allocations in 500 samples' records"
    );
    println!("the physics step: {in_step} allocations in 500 samples");
}
