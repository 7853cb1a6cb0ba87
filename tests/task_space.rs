//! The report in the task space: a URDF arm's tracking error is its tool against the
//! target the slave was given after the master's workspace map (per-axis scale, a
//! rotation between the bases, the clutch's offsets), in the arm's base frame, and a
//! run with a clutch says how long it was released. The figures are checked against
//! an independent computation from `trace.csv` and `joints.csv`: the tool and v(n) in
//! the master's frame, through the map by hand, less the clutch's offset.

use crate::util;

use std::path::Path;
use util::{column, Sandbox};

/// The map's rotation, rpy (90, 0, -90) degrees (Rz(-90) Rx(90)): the master's `u`
/// is the arm's `R u`.
const R: [[f64; 3]; 3] = [[0.0, 0.0, -1.0], [-1.0, 0.0, 0.0], [0.0, 1.0, 0.0]];
/// The map's scale per base axis.
const S: [f64; 3] = [1.5, 1.2, 0.8];

/// A 3 s trajectory at 25 ms rows: a diagonal stroke, the clutch released from 1.2 s
/// to 2 s while the hand goes back home, then the stroke again turning 20 degrees
/// about the master's z.
fn trajectory() -> String {
    let home = [0.0, -0.107, -0.035];
    let stroke = [0.02, 0.01, -0.03];
    let jerk = util::min_jerk;
    let mut text = String::from("t,x,y,z,qx,qy,qz,qw,engaged\n");
    for k in 0..=120 {
        let t = k as f64 * 0.025;
        let (along, turn, engaged) = match t {
            t if t < 1.2 => (jerk(t), 0.0, 1),
            t if t < 2.0 => (1.0 - jerk((t - 1.2) / 0.6), 0.0, 0),
            t => (jerk(t - 2.0), jerk(t - 2.0), 1),
        };
        let p = [0, 1, 2].map(|i| home[i] + along * stroke[i]);
        let h = (20.0f64 * turn).to_radians() / 2.0;
        text += &format!(
            "{t:.3},{:.9},{:.9},{:.9},0,0,{:.12},{:.12},{engaged}\n",
            p[0],
            p[1],
            p[2],
            h.sin(),
            h.cos()
        );
    }
    text
}

fn scenario(csv: &Path, urdf: &Path) -> String {
    format!(
        r#"name = "task-space"
mode = "lockstep"
rate_hz = 1000.0
samples = 3000
arithmetic = "hybrid"
device = "paper"

[operator]
kind = "csv"
path = {csv:?}

[slave.arm]
urdf = {urdf:?}
base = "panda_link0"
tip = "panda_hand"
home = [0.0, -0.785398, 0.0, -2.356194, 0.0, 1.570796, 0.785398]
kp = [600.0, 600.0, 600.0, 600.0, 250.0, 150.0, 50.0]
kd = [50.0, 50.0, 50.0, 50.0, 30.0, 25.0, 15.0]
rotation = {{ rpy_deg = [90.0, 0.0, -90.0] }}
scale = [1.5, 1.2, 0.8]
force_scale = 0.5
workspace = {{ min = [0.2, -0.5, 0.1], max = [0.8, 0.5, 0.9] }}
"#
    )
}

/// The angle between two unit quaternions, degrees.
fn angle(a: [f64; 4], b: [f64; 4]) -> f64 {
    let dot: f64 = (0..4).map(|i| a[i] * b[i]).sum();
    2.0 * dot.abs().min(1.0).acos().to_degrees()
}

/// The figure printed after `label` in the report's text, in its unit.
fn printed(text: &str, label: &str) -> f64 {
    let at = text
        .find(label)
        .unwrap_or_else(|| panic!("no {label:?} in {text}"));
    let rest = &text[at + label.len()..];
    let end = rest.find(' ').expect("a unit after the figure");
    rest[..end].parse().expect("a number")
}

#[test]
fn the_tracking_error_is_the_tool_against_its_mapped_target_with_the_clutch_apart() {
    let sb = Sandbox::new("taskspace");
    let csv = sb.write("strokes.csv", &trajectory());
    let urdf = Path::new(env!("CARGO_MANIFEST_DIR")).join("robots/panda.urdf");
    let file = sb.write("task.toml", &scenario(&csv, &urdf));
    let out = sb.path("a");
    let (file, dir) = (file.to_str().expect("utf-8"), out.to_str().expect("utf-8"));
    let o = sb.tactile(&["run", file, "--in-process", "--out", dir]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let text = String::from_utf8_lossy(&o.stdout).to_string();
    let trace = sb.trace("a");
    let joints = std::fs::read_to_string(out.join("joints.csv")).expect("joints");
    let s = sb.json("a", "summary.json");
    assert_eq!(
        s["slave"]["counters"]["workspace_clamped"], 0,
        "no target clamped"
    );

    // Engaged: the tool's distance from its target in the base frame is
    // S R (tool - v) less the offset captured at the engage (home and the master's
    // home cancel out).
    let cols = |text: &str, c: &str| [1, 2, 3].map(|i| column(text, &format!("{c}_{i}")));
    let (tool, v, offset) = (
        cols(&trace, "tool"),
        cols(&trace, "v"),
        cols(&joints, "offset"),
    );
    let quat = |c: &str| ["x", "y", "z", "w"].map(|k| column(&joints, &format!("{c}_rot_{k}")));
    let (target_rot, tool_rot) = (quat("target"), quat("tool"));
    let released = column(&joints, "released");
    let (mut sq, mut max, mut rot_sq, mut engaged) = (0.0, 0.0f64, 0.0, 0u64);
    for n in (0..released.len()).filter(|&n| released[n] == 0.0) {
        let d: [f64; 3] = [0, 1, 2].map(|k| tool[k][n] - v[k][n]);
        let e: f64 = (0..3)
            .map(|i| S[i] * (0..3).map(|k| R[i][k] * d[k]).sum::<f64>() - offset[i][n])
            .map(|x| x * x)
            .sum();
        let a = angle(
            [0, 1, 2, 3].map(|k| target_rot[k][n]),
            [0, 1, 2, 3].map(|k| tool_rot[k][n]),
        );
        (sq, max, rot_sq, engaged) = (sq + e, max.max(e.sqrt()), rot_sq + a * a, engaged + 1);
    }
    let rms = (sq / engaged as f64).sqrt();
    let ts = &s["task_space"];
    assert_eq!(ts["engaged_samples"], engaged);
    let near = |got: &serde_json::Value, want: f64, tol: f64| {
        let g = util::num(got);
        assert!((g - want).abs() <= tol, "{g} against {want}");
    };
    near(&ts["position_rms_m"], rms, 1e-12);
    near(&ts["position_max_m"], max, 1e-12);
    near(
        &ts["rotation_rms_deg"],
        (rot_sq / engaged as f64).sqrt(),
        1e-4,
    );
    // The clutch: the file releases from 1.2 s to 2 s, one engage after it.
    let held = released.iter().filter(|r| **r == 1.0).count() as u64;
    assert_eq!(ts["released_samples"], held);
    assert!((800..=801).contains(&held), "{held} samples released");
    assert_eq!(ts["engages"], 1);
    near(&ts["released_s"], held as f64 * 1e-3, 1e-12);
    // The offsets are not zero after the engage: a measure against v(n) alone would
    // count them as error.
    let last = offset[0].len() - 1;
    assert!(offset.iter().map(|o| o[last].abs()).fold(0.0, f64::max) > 1e-3);
    assert!(rms < 2e-3, "tracking rms {rms} m");

    // The text prints the same figures.
    let line = text
        .lines()
        .find(|l| l.starts_with("tracking error (tool against its target after the map"))
        .unwrap_or_else(|| panic!("no task-space line in {text}"));
    assert!(
        (printed(line, "position rms ") - rms * 1e3).abs() < 6e-4,
        "{line}"
    );
    assert!((printed(line, ", max ") - max * 1e3).abs() < 6e-4, "{line}");
    assert!(
        text.contains(&format!(
            "clutch: released {held} samples ({:.3} s), 1 engages",
            held as f64 * 1e-3
        )),
        "{text}"
    );
}
