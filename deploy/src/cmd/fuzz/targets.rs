//! The decoders of outside bytes that `tactile fuzz` drives, each with seeds made by
//! the encoder of the same format (valid inputs the mutations start from), and an
//! outcome in words (`ok`, or the error), whose shape tells the inputs' paths apart.

use std::io::Write as _;
use std::path::Path;
use tactile_messages::samples::{Backward, Forward};
use tactile_records::emulator::{EmulatorTotals, Passage};
use tactile_records::master::{MasterSample, MasterTotals};
use tactile_records::slave::{SlaveSample, SlaveTotals};
use tactile_records::{Record, RecordReader};
use tactile_ros::msg::{Decode, Float64MultiArray, JointState, Message, WrenchStamped};

/// A decoder over one input, its outcome in words.
pub type Run = Box<dyn Fn(&[u8]) -> String>;

/// One decoder: its name, its seeds, and a run over one input.
pub struct Target {
    /// As `--target` names it.
    pub name: &'static str,
    /// Valid inputs to start from.
    pub seeds: Vec<Vec<u8>>,
    /// Tokens of the format that mutations put in place of a number or insert (the
    /// values and names byte flips seldom make: `1e308`, `nan`, `"fixed"`); none for
    /// a binary format.
    pub dict: &'static [&'static str],
    /// Decodes one input; the outcome in words.
    pub run: Run,
}

pub fn outcome<T, E: std::fmt::Display>(r: Result<T, E>) -> String {
    r.map_or_else(|e| e.to_string(), |_| "ok".into())
}

/// A record's sample block past its checksum (what a crafted record, or another
/// build's, hands the reader): the planes' layout unpacked, the rows it claims taken
/// from its first varint so the deeper paths are reached.
pub(super) fn blocks() -> Target {
    use tactile_records::block;
    let mut seeds = Vec::new();
    for (rows, len) in [(50usize, 24usize), (7, 9)] {
        let flat: Vec<u8> = (0..rows * len).map(|i| (i * 37 % 251) as u8).collect();
        let mut planes = Vec::new();
        block::to_planes(&flat, &vec![len; rows], &mut planes, &mut Vec::new());
        seeds.push(planes);
    }
    Target {
        name: "blocks",
        seeds,
        dict: &[],
        run: Box::new(|b| {
            let rows = b.first().map_or(0, |r| u32::from(r & 0x7f));
            outcome(block::from_planes(b, rows))
        }),
    }
}

/// The three nodes' record files: the reader of each role over the same bytes.
pub(super) fn records(scratch: &Path) -> Result<Target, String> {
    let out = scratch.join("seed-run");
    let text = tactile_launch::PAPER_SCENARIO.replace("samples = 1200", "samples = 30");
    let scenario = tactile_scenario::Scenario::from_toml_str(&text).map_err(|e| e.to_string())?;
    std::fs::create_dir_all(&out).map_err(|e| e.to_string())?;
    tactile_launch::sim::simulate(&scenario, scratch, &out, Default::default())
        .map_err(|e| e.to_string())?;
    let seeds = ["master", "emulator", "slave"]
        .iter()
        .map(|r| std::fs::read(out.join(format!("{r}.rec"))).map_err(|e| e.to_string()))
        .collect::<Result<_, _>>()?;
    let file = scratch.join("input.rec");
    Ok(Target {
        name: "records",
        seeds,
        dict: &[],
        run: Box::new(move |b| {
            if std::fs::File::create(&file)
                .and_then(|mut f| f.write_all(b))
                .is_err()
            {
                return "scratch file not written".into();
            }
            [
                read_all::<MasterSample, MasterTotals>(&file),
                read_all::<Passage, EmulatorTotals>(&file),
                read_all::<SlaveSample, SlaveTotals>(&file),
            ]
            .join(" / ")
        }),
    })
}

fn read_all<S: serde::de::DeserializeOwned, C: serde::de::DeserializeOwned>(p: &Path) -> String {
    let mut r = match RecordReader::<Record<S, C>>::open(p) {
        Ok(r) => r,
        Err(e) => return e.to_string(),
    };
    let mut n = 0u64;
    loop {
        match r.next_record() {
            Ok(Some(_)) => n += 1,
            Ok(None) => break,
            Err(e) => return e.to_string(),
        }
    }
    // Counts bucketed (none, one, a few, many): a path, not a number.
    let bucket = |k: u64| ["none", "one", "few", "many"][k.min(2) as usize + usize::from(k > 9)];
    format!("{} records, {} damaged", bucket(n), bucket(r.damaged().1))
}

/// The ROS 2 messages the nodes take in from drivers.
pub(super) fn cdr() -> Target {
    let joints = JointState {
        name: vec!["waist".into(), "shoulder".into(), "elbow".into()],
        position: vec![0.1, -0.2, 0.3],
        velocity: vec![0.0; 3],
        effort: vec![],
        ..JointState::default()
    };
    let wrench = WrenchStamped::default();
    let array = Float64MultiArray {
        data: vec![1.0, 2.0, 3.0],
    };
    Target {
        name: "cdr",
        seeds: vec![joints.to_cdr(), wrench.to_cdr(), array.to_cdr()],
        dict: &[],
        run: Box::new(|b| {
            [
                outcome(JointState::from_cdr(b)),
                outcome(WrenchStamped::from_cdr(b)),
                outcome(Float64MultiArray::from_cdr(b)),
            ]
            .join(" / ")
        }),
    }
}

/// The loop's samples on UDP and Zenoh.
pub(super) fn wire() -> Target {
    let mut f = Vec::new();
    let mut b = Vec::new();
    let _ = tactile_transport::wire::encode(&Forward::default(), &mut f);
    let _ = tactile_transport::wire::encode(&Backward::default(), &mut b);
    Target {
        name: "wire",
        seeds: vec![f, b],
        dict: &[],
        run: Box::new(|b| match tactile_transport::wire::decode(b) {
            Ok(tactile_transport::wire::Frame::Forward(_)) => "forward".into(),
            Ok(tactile_transport::wire::Frame::Backward(_)) => "backward".into(),
            Err(e) => format!("{e:?}"),
        }),
    }
}

/// rmw_zenoh's attachment on every ROS 2 sample.
pub(super) fn attachment() -> Target {
    let a = tactile_ros::rmw::Attachment {
        seq: 7,
        stamp_ns: 1_700_000_000_000_000_000,
        gid: [3; 16],
    };
    Target {
        name: "attachment",
        seeds: vec![a.to_bytes().to_vec()],
        dict: &[],
        run: Box::new(|b| {
            tactile_ros::rmw::Attachment::from_bytes(b).map_or("none".into(), |_| "ok".into())
        }),
    }
}

/// Scenario files.
pub(super) fn scenario() -> Target {
    let seeds = [
        tactile_launch::PAPER_SCENARIO,
        include_str!("../../../scenarios/wall-delay.toml"),
    ];
    Target {
        name: "scenario",
        seeds: seeds.iter().map(|s| s.as_bytes().to_vec()).collect(),
        dict: &[],
        run: Box::new(|b| {
            outcome(tactile_scenario::Scenario::from_toml_str(
                &String::from_utf8_lossy(b),
            ))
        }),
    }
}

/// Operator trajectory files (CSV, timed or not).
pub(super) fn trajectory() -> Target {
    let seeds = [
        "x,y,z\n0.1,0.0,-0.1\n0.11,0.01,-0.12\n",
        "t,x,y,z\n0,0.1,0.0,-0.1\n0.5,0.11,0.01,-0.12\n1.0,0.1,0.0,-0.1\n",
    ];
    Target {
        name: "trajectory",
        seeds: seeds.iter().map(|s| s.as_bytes().to_vec()).collect(),
        dict: &[],
        run: Box::new(|b| {
            outcome(tactile_master::trajectory::Trajectory::parse(
                &String::from_utf8_lossy(b),
                "fuzz.csv".into(),
                tactile_scenario::TrajectoryEnd::default(),
            ))
        }),
    }
}

/// `tactile kernels` input (CSV on stdin), for each kernel in the hybrid arithmetic.
pub(super) fn kernels() -> Target {
    use clap::Parser;
    #[derive(Parser)]
    struct K {
        #[command(flatten)]
        k: crate::cmd::kernels::KernelsArgs,
    }
    let args: Vec<_> = ["fk", "ik", "kff", "fbf"]
        .iter()
        .filter_map(|m| K::try_parse_from(["k", m, "--arith", "hybrid"]).ok())
        .map(|k| k.k)
        .collect();
    let seeds = [
        "theta1,theta2,theta3\n0.1,0.2,0.3\n",
        "x,y,z\n0.0,0.1,-0.1\n",
        "theta1,theta2,theta3,fx,fy,fz\n0.1,0.2,0.3,1,0,-1\n",
        "x_obj,y_obj,z_obj,x_env,y_env,z_env,hx,hy,hz\n0,0,-0.1,0,0,-0.12,100,100,100\n",
    ];
    Target {
        name: "kernels",
        seeds: seeds.iter().map(|s| s.as_bytes().to_vec()).collect(),
        dict: &[],
        run: Box::new(move |b| {
            args.iter()
                .map(|a| {
                    let mut out = Vec::new();
                    outcome(crate::cmd::kernels::run(a, b, &mut out))
                })
                .collect::<Vec<_>>()
                .join(" / ")
        }),
    }
}
