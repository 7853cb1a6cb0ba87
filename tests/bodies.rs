//! A physics world's bodies in a run's files (docs/16, "The views"): the slave's
//! record holds the moving bodies' poses each sample, `bodies.csv` is those poses,
//! `run.mcap` draws every body at them (checked by an independent reader, mcap_ros2,
//! tests/mcap_bodies_check.py), `task.svg` plots the task's progress, and an analytic
//! run writes none of it.

use crate::util::{self, Sandbox};
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use tactile_records::slave::{SlaveSample, SlaveTotals};
use tactile_records::{Record, RecordReader};

fn shipped(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../deploy/scenarios")
        .join(name)
}

/// Each step's world, read from the slave's record with the records crate alone:
/// (sample, body) -> [x, y, z, qx, qy, qz, qw], the tool as `tool`.
fn recorded(rec: &Path, names: &[&str]) -> BTreeMap<(u64, String), [f64; 7]> {
    let mut r = RecordReader::<Record<SlaveSample, SlaveTotals>>::open(rec).expect("record");
    let mut out = BTreeMap::new();
    while let Some(x) = r.next_record().expect("readable") {
        let Record::Sample(SlaveSample::Step(step, _, world)) = x else {
            continue;
        };
        let w = world.expect("a physics run's step holds its world");
        let mut put = |name: &str, p: &tactile_records::slave::BodyPose| {
            let [x, y, z] = p.position;
            let [a, b, c, d] = p.rotation;
            out.insert((step.n, name.to_string()), [x, y, z, a, b, c, d]);
        };
        put("tool", &w.tool);
        for (k, p) in w.poses() {
            put(names[k], p);
        }
    }
    out
}

/// `bodies.csv` as a map like [`recorded`]'s.
fn table(path: &Path) -> BTreeMap<(u64, String), [f64; 7]> {
    let text = std::fs::read_to_string(path).expect("bodies.csv");
    let mut lines = text.lines();
    assert_eq!(lines.next(), Some("sample,body,x,y,z,qx,qy,qz,qw"));
    lines
        .map(|l| {
            let f: Vec<&str> = l.split(',').collect();
            let v: Vec<f64> = f[2..].iter().map(|x| x.parse().expect("number")).collect();
            let n: u64 = f[0].parse().expect("sample");
            ((n, f[1].to_string()), v.try_into().expect("seven numbers"))
        })
        .collect()
}

#[test]
fn the_pushed_box_moves_in_the_record_the_table_and_the_recording() {
    let sb = Sandbox::new("bodies");
    sb.simulate(&shipped("push-box.toml"), "a");
    let rec = recorded(&sb.path("a").join("slave.rec"), &["box"]);
    let csv = table(&sb.path("a").join("bodies.csv"));
    // Every step's tool and box, bit for bit as recorded.
    assert_eq!(rec.len(), 2 * 7000);
    assert_eq!(csv, rec);
    // The box was pushed 8 cm along x, to within 1 cm of its target at x = 5 cm.
    let x0 = csv[&(0, "box".to_string())][0];
    let x1 = csv[&(6999, "box".to_string())][0];
    assert!(x0.abs() < 1e-3 && (x1 - 0.05).abs() < 0.01, "{x0} -> {x1}");
    // The task's progress, its target and when it succeeded.
    let svg = std::fs::read_to_string(sb.path("a").join("task.svg")).expect("task.svg");
    let s = sb.json("a", "summary.json");
    let done = util::num(&s["task"]["completion_s"]);
    for want in [
        "Task progress: succeeded".to_string(),
        "tolerance 10 mm".to_string(),
        format!("success at {done:.3} s"),
    ] {
        assert!(svg.contains(&want), "task.svg lacks {want}");
    }
    assert!(
        svg.matches("<polyline").count() >= 2,
        "no lines in task.svg"
    );
    if !util::python_has("mcap, mcap_ros2, numpy, trimesh") {
        return util::cannot("python3 lacks mcap, mcap-ros2-support, numpy or trimesh");
    }
    let out = mcap_bodies_check(&sb, "a", "slave_base");
    assert!(
        out.contains("checked 7000 samples, 1 moving bodies, 1 static"),
        "{out}"
    );
}

/// tests/mcap_bodies_check.py on the report in `out`, the bodies in `frame`.
fn mcap_bodies_check(sb: &Sandbox, out: &str, frame: &str) -> String {
    let script = concat!(env!("CARGO_MANIFEST_DIR"), "/../tests/mcap_bodies_check.py");
    let o = std::process::Command::new("python3")
        .arg(script)
        .arg(sb.path(out))
        .args(["--frame", frame])
        .output()
        .expect("python3");
    let text = String::from_utf8_lossy(&o.stdout).to_string();
    assert!(
        o.status.success(),
        "{text}{}",
        String::from_utf8_lossy(&o.stderr)
    );
    text
}

/// The peg-in-hole's block is a mesh: drawn as its file's triangles; a Panda's world
/// is drawn in its base link, where the arm's tool is.
#[test]
fn a_mesh_is_drawn_as_its_triangles_and_a_urdf_arms_world_in_its_base() {
    if !util::python_has("mcap, mcap_ros2, numpy, trimesh") {
        return util::cannot("python3 lacks mcap, mcap-ros2-support, numpy or trimesh");
    }
    let sb = Sandbox::new("bodymesh");
    sb.simulate(&shipped("peg-in-hole.toml"), "peg");
    let out = mcap_bodies_check(&sb, "peg", "slave_base");
    assert!(out.contains("0 moving bodies, 1 static"), "{out}");
    sb.simulate(&shipped("panda-push-box.toml"), "panda");
    let out = mcap_bodies_check(&sb, "panda", "panda_link0");
    assert!(out.contains("1 moving bodies, 1 static"), "{out}");
}

/// The analytic scene records no world, and its report has no bodies or task plot.
#[test]
fn an_analytic_run_records_no_world_and_writes_no_bodies() {
    let sb = Sandbox::new("nobodies");
    let text = std::fs::read_to_string(shipped("wall-delay.toml"))
        .expect("wall-delay")
        .replace("samples = ", "samples = 300 # ");
    let scenario = sb.write("short.toml", &text);
    sb.simulate(&scenario, "a");
    let mut r =
        RecordReader::<Record<SlaveSample, SlaveTotals>>::open(&sb.path("a").join("slave.rec"))
            .expect("record");
    let mut steps = 0;
    while let Some(x) = r.next_record().expect("readable") {
        if let Record::Sample(s) = x {
            assert!(s.world().is_none());
            steps += 1;
        }
    }
    assert!(steps > 0);
    assert!(!sb.path("a").join("bodies.csv").exists());
    assert!(!sb.path("a").join("task.svg").exists());
}
