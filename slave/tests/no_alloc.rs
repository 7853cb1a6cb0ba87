//! The simulated arm's integration allocates nothing once warm (issue 52): a counting
//! global allocator, counting only on the thread that steps the arm, so the test
//! harness's own threads do not disturb the count. One test in this binary, so no
//! other test shares the allocator.

// A global allocator is unsafe by its trait: it only forwards to the system's.
#![allow(unsafe_code)]

use std::alloc::{GlobalAlloc, Layout, System};
use std::cell::Cell;
use std::path::Path;
use std::sync::atomic::{AtomicU64, Ordering};
use tactile_scenario::{ArmServo, Object, Scenario};
use tactile_slave::environment::Scene;
use tactile_slave::urdf_arm::UrdfArm;

/// The system's allocator, counting the allocations of a thread that asked for it.
struct Counting;

static ALLOCATIONS: AtomicU64 = AtomicU64::new(0);

thread_local! {
    static COUNTING: Cell<bool> = const { Cell::new(false) };
}

fn count() {
    if COUNTING.with(Cell::get) {
        ALLOCATIONS.fetch_add(1, Ordering::Relaxed);
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
    let before = ALLOCATIONS.load(Ordering::Relaxed);
    COUNTING.with(|c| c.set(true));
    f();
    COUNTING.with(|c| c.set(false));
    ALLOCATIONS.load(Ordering::Relaxed) - before
}

/// The paper master's home, where the operator of `panda.toml` starts.
const HOME: [f64; 3] = [0.0, -0.107, -0.035];

/// The shipped Panda scenario's arm (4 integration steps a sample) under `servo`, in
/// a wall above its home: the contact's efforts are computed at every step.
fn panda(servo: ArmServo) -> (UrdfArm, Scene) {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("../deploy/scenarios");
    let text = std::fs::read_to_string(dir.join("panda.toml")).expect("panda.toml");
    let scenario = Scenario::from_toml_str(&text).expect("the panda scenario");
    let mut cfg = scenario.slave.arm.expect("a [slave.arm]");
    cfg.servo = servo;
    let xml = std::fs::read_to_string(dir.join(&cfg.urdf)).expect("panda.urdf");
    let arm = UrdfArm::new(&cfg, &xml, HOME).expect("the panda");
    let wall = Object::Plane {
        point: [0.0, 0.0, 0.0],
        normal: [0.0, 0.0, 1.0],
        stiffness: [600.0; 3],
    };
    (arm, Scene::new(&[wall]))
}

/// Allocations in 200 samples of integration, 200 more of holding, and the tool read
/// after each as the slave's handler reads it, after a warm-up of 10 samples.
fn allocations_in_400_samples(servo: ArmServo) -> u64 {
    let (mut arm, scene) = panda(servo);
    for _ in 0..10 {
        arm.follow([HOME[0], HOME[1], HOME[2] - 0.06], None, 1e-3);
        arm.advance(1e-3, &scene);
    }
    arm.hold(1e-3, &scene);
    let mut seen = 0.0;
    let n = allocations(|| {
        for _ in 0..200 {
            arm.advance(1e-3, &scene);
            arm.hold(1e-3, &scene);
            seen += arm.tool()[2] + arm.tool_rotation()[3];
        }
    });
    assert!(seen.is_finite() && arm.dynamics_failures() == 0);
    n
}

/// Issue 52: the joint servo's integration allocates nothing once warm; the
/// Cartesian servo only the packing buffers of its three 7-column matrix products
/// (nalgebra hands them to `matrixmultiply`, which allocates them per call), 3 an
/// integration step, 4 steps a sample.
#[test]
fn the_arms_integration_allocates_nothing_once_warm() {
    let joint = allocations_in_400_samples(ArmServo::Joint);
    assert_eq!(joint, 0, "joint servo: {joint} allocations in 400 samples");
    let cartesian = allocations_in_400_samples(ArmServo::Cartesian);
    assert!(
        cartesian <= 3 * 4 * 400,
        "Cartesian servo: {cartesian} allocations in 400 samples"
    );
}
