//! A 6-DoF operator's trajectory CSV (`t,x,y,z,qx,qy,qz,qw,engaged` and the forms
//! without a time, an orientation or a clutch): parsed as the master reads it, then
//! played as a run plays it, at rates and sample numbers from the first to far past
//! the file's end, held and looped. Whatever is accepted must play: every position
//! finite, every orientation a unit quaternion; a value that is not panics here, which
//! the campaign counts and keeps.

use super::arm::finite;
use super::targets::Target;
use tactile_master::trajectory::Trajectory;
use tactile_scenario::TrajectoryEnd;

/// The shipped 6-DoF files' first rows (their strokes and turns), and the forms
/// they do not use.
fn seeds() -> Vec<Vec<u8>> {
    let head = |text: &str, rows: usize| {
        let lines: Vec<&str> = text.lines().take(rows).collect();
        format!("{}\n", lines.join("\n"))
    };
    let reach = include_str!("../../../scenarios/panda-reach.csv");
    let pose = include_str!("../../../scenarios/panda-pose.csv");
    [
        head(reach, 40),
        head(pose, 30),
        // Past the first stroke: the clutch let go.
        format!(
            "{}\n{}",
            head(reach, 1),
            reach
                .lines()
                .skip(85)
                .take(20)
                .collect::<Vec<_>>()
                .join("\n")
        ),
        "x,y,z,qx,qy,qz,qw\n0,-0.107,-0.035,0,0,0,1\n0.01,-0.1,-0.03,0,0,0.0998,0.995\n".into(),
        "x,y,z,engaged\n0,-0.107,-0.035,1\n0.01,-0.1,-0.03,0\n".into(),
        "t,x,y,z,qx,qy,qz,qw\n0,0,-0.107,-0.035,0,0,0,1\n0.5,0,-0.1,-0.03,0,0,-0.0998,-0.995\n"
            .into(),
    ]
    .into_iter()
    .map(String::into_bytes)
    .collect()
}

/// The target.
pub fn trajectory6() -> Target {
    Target {
        name: "trajectory6",
        seeds: seeds(),
        dict: &[
            "1e308",
            "-1e308",
            "1e-300",
            "5e-324",
            "0",
            "-0",
            "1",
            "2",
            "0.5",
            "nan",
            "inf",
            "0,0,0,1",
            "0,0,0,-1",
            "0.7071,0.7071,0,0",
            "1.0005",
            "t,",
            ",engaged",
            ",qx,qy,qz,qw",
        ],
        run: Box::new(|b| {
            let text = String::from_utf8_lossy(b);
            let mut out = Vec::new();
            for end in [TrajectoryEnd::Hold, TrajectoryEnd::Loop] {
                out.push(match Trajectory::parse(&text, "fuzz.csv".into(), end) {
                    Ok(t) => played(&t),
                    Err(e) => e.to_string(),
                });
            }
            out.join(" / ")
        }),
    }
}

/// An accepted file played: each sample's position, orientation and clutch, and what
/// the run would be warned of.
fn played(t: &Trajectory) -> String {
    for t_s in [1e-3, 2.5e-4, 0.1] {
        for n in [0, 1, 2, 3, 39, 40, 41, 999, 12_345, 1 << 20, 1 << 40] {
            finite("a position", t.at(n, t_s));
            if let Some(q) = t.rotation_at(n, t_s) {
                finite("an orientation", q);
                let norm = q.iter().map(|v| v * v).sum::<f64>().sqrt();
                // nalgebra's slerp takes sin(h) as sqrt(1 - cos^2 h): between rows
                // 1e-4 rad apart its result's norm is 1 - 1.9e-9 (the campaign of
                // docs/12 found it), a rotation to far better than a micrometre.
                assert!((norm - 1.0).abs() < 1e-6, "sample {n}: orientation {q:?}");
            }
            t.engaged_at(n, t_s);
        }
        for samples in [1, 2, 1000, 1 << 30] {
            t.shortfall(samples, t_s);
        }
    }
    format!(
        "ok{}{}",
        if t.oriented() { " oriented" } else { "" },
        if t.clutched() { " clutched" } else { "" }
    )
}
