//! The summary as the terminal shows it: a few lines per part of the run (timing,
//! samples, motion and forces, the counters, devices, nodes, events), each part a
//! function of its own.

use crate::analysis::{rounding_note, us_header, us_line};
use crate::summary::{Summary, REPORT_FILES};
use std::fmt::Write as _;
use std::path::Path;

/// The summary as the terminal shows it.
pub fn render(s: &Summary, out: &Path) -> String {
    let mut t = String::new();
    let _ = writeln!(
        t,
        "Tactile run {:?}: {:?} at {} Hz, {} arithmetic, {}",
        s.scenario, s.mode, s.rate_hz, s.arithmetic, s.runner
    );
    // First: a figure below may come from a part of the run only.
    for w in &s.warnings {
        let _ = writeln!(t, "warning: {w}");
    }
    timing(&mut t, s);
    samples(&mut t, s);
    motion(&mut t, s);
    if let Some(task) = &s.task {
        task_line(&mut t, task);
    }
    counters(&mut t, s);
    if let Some(h) = &s.hardware {
        for line in crate::hardware::lines(h, &s.stages_ns) {
            let _ = writeln!(t, "{line}");
        }
    }
    devices(&mut t, s);
    nodes(&mut t, s);
    let files: Vec<&str> = REPORT_FILES
        .iter()
        .copied()
        .filter(|f| out.join(f).exists())
        .collect();
    let _ = writeln!(t, "wrote {}: {}", out.display(), files.join(" "));
    t
}

/// Millimetres, or n/a.
fn mm(v: Option<f64>) -> String {
    v.map_or("n/a".to_string(), |x| format!("{:.2} mm", x * 1e3))
}

/// Round trip, overhead and stages, and the clocks.
fn timing(t: &mut String, s: &Summary) {
    if let (Some(p), Some(ms)) = (&s.round_trip_samples, s.round_trip_ms_nominal) {
        let _ = writeln!(
            t,
            "round trip (lockstep): {} samples p50 ({ms:.1} ms nominal), p99 {}, max {} ({} answers)",
            p.p50, p.p99, p.max, p.count
        );
    }
    if let Some(why) = s.overhead_na {
        let _ = writeln!(t, "system overhead: n/a ({why})");
    }
    // The header only over rows (a lockstep run in process has none).
    if s.overhead_na.is_none() || !s.stages_ns.is_empty() {
        let _ = writeln!(t, "{}", us_header());
    }
    if s.overhead_na.is_none() {
        let _ = writeln!(t, "{}", us_line("round trip", s.round_trip_ns.as_ref()));
        let _ = writeln!(t, "{}", us_line("system overhead", s.overhead_ns.as_ref()));
    }
    for (name, p) in &s.stages_ns {
        let _ = writeln!(t, "{}", us_line(&format!("  {name}"), Some(p)));
    }
    let rows = [&s.round_trip_ns, &s.overhead_ns].into_iter().flatten();
    let rows = rows.filter(|_| s.overhead_na.is_none());
    if let Some(note) = rounding_note(rows.chain(s.stages_ns.values())) {
        let _ = writeln!(t, "{note}");
    }
    if !s.clocks.shared {
        let _ = writeln!(
            t,
            "clocks: the nodes do not share one clock; stages between them are left out"
        );
        for o in &s.clocks.offsets {
            let _ = writeln!(
                t,
                "  {} clock offset (estimate): {:.3} ms +- {:.1} us ({} exchanges, shortest network round trip {:.1} us)",
                o.between,
                o.offset_ns_estimate as f64 / 1e6,
                o.uncertainty_ns as f64 / 1e3,
                o.exchanges,
                o.min_network_round_trip_ns as f64 / 1e3
            );
        }
    }
}

/// Samples sent, received and lost, per stream.
fn samples(t: &mut String, s: &Summary) {
    let m = &s.master;
    let _ = writeln!(
        t,
        "samples: sent {}, received {}, lost {}; deadline misses {}, late {}",
        s.samples_sent, s.samples_received, s.samples_lost, s.deadline_misses, m.totals.late
    );
    for (name, c) in &s.channels {
        let _ = writeln!(
            t,
            "  stream {name}: sent {}, received {}, lost {} (dropped {}, overwritten {}, dead peer {})",
            c.offered, c.received, c.lost, c.lost_dropped, c.lost_overwritten, c.lost_dead_peer
        );
    }
}

/// Tracking, forces, the bilateral figures and passivity.
fn motion(t: &mut String, s: &Summary) {
    let m = &s.master;
    let mo = &m.motion;
    match &s.task_space {
        Some(ts) => task_space(t, ts),
        None => {
            let _ = writeln!(
                t,
                "tracking error (slave tool against the v(n) it was sent): rms {}, max {}",
                mm(mo.tracking_rms_m),
                mm(mo.tracking_max_m)
            );
        }
    }
    // h(n) is the environment's force as sent; a URDF arm's is the robot's scaled.
    let sent = match &s.task_space {
        Some(ts) => format!(
            "h(n) sent max {:.3} N (the robot's {:.3} N times force_scale {})",
            mo.force_max_n, ts.robot_force_max_n, ts.force_scale
        ),
        None => format!("environment's force h(n) max {:.3} N", mo.force_max_n),
    };
    let _ = writeln!(
        t,
        "forces: {} samples in contact, {sent}, felt rms {} max {:.3} N, master torque max {:.4} N m",
        mo.contact_samples,
        mo.felt_rms_n.map_or("n/a".to_string(), |f| format!("{f:.3} N")),
        mo.felt_max_n,
        mo.tau_max_nm
    );
    let _ = writeln!(
        t,
        "bilateral ({} hand, control {}): position rms {} against the delay-shifted handle{}, force tracking error rms {} (felt against the environment's force it came from), penetration max {:.2} mm, felt force's largest step {:.3} N",
        match s.hand {
            tactile_scenario::HandMode::Position => "position",
            tactile_scenario::HandMode::Impedance => "impedance",
        },
        s.control,
        mm(s.tracking.position_rms_m),
        // The handle moved by the clutch's offsets, released samples left out (as the
        // task-space line above does).
        match &s.task_space {
            Some(ts) if ts.released_samples > 0 => " (the master's frame, the handle moved by the clutch's offsets, released samples left out)",
            _ => "",
        },
        s.tracking.force_rms_n.map_or("n/a".to_string(), |f| format!("{f:.3} N")),
        s.contact.max_penetration_m * 1e3,
        s.contact.felt_step_max_n
    );
    let tr = &s.transparency;
    let stiffness = |k: Option<f64>| k.map_or("n/a".to_string(), |k| format!("{k:.0} N/m"));
    let _ = writeln!(
        t,
        "transparency: felt stiffness {} against the environment's {} (ratio {}), from {} master samples behind the surface and {} slave steps in contact",
        stiffness(tr.felt_stiffness_n_per_m),
        stiffness(tr.environment_stiffness_n_per_m),
        tr.stiffness_ratio.map_or("n/a".to_string(), |r| format!("{r:.2}")),
        tr.felt_samples,
        tr.environment_samples
    );
    // A wall's figure: a physics world's surface is wherever the tool met a body.
    let physics = s.slave.as_ref().is_some_and(|sl| sl.world.physics);
    if let (Some(d), Some(e), false) = (tr.unfelt_depth_m, tr.unfelt_energy_j, physics) {
        let _ = writeln!(
            t,
            "first news of the contact: the handle {:.2} mm deep, {:.3} mJ of the wall unfelt (what rendering it where it is leaves the channel short)",
            d * 1e3,
            e * 1e3
        );
    }
    if let Some(m) = &s.mmt {
        let _ = writeln!(
            t,
            "model (mmt): {} models sent, {} taken, {} refused; converged {} after first contact; felt stiffness since {} (ratio {}) from {} master samples; model changes added {:.3} mJ at the handle",
            m.models_sent,
            m.models_taken,
            m.models_refused,
            tr.model_convergence_ms.map_or("never".to_string(), |ms| format!("{ms:.0} ms")),
            stiffness(tr.felt_stiffness_converged_n_per_m),
            tr.stiffness_ratio_converged.map_or("n/a".to_string(), |r| format!("{r:.2}")),
            tr.felt_converged_samples,
            m.injected_j * 1e3,
        );
    }
    let _ = writeln!(
        t,
        "passivity: observer min {}, dissipated {:.3} mJ, drift max {}; packets forward {}, backward {}",
        s.passivity.observer_min_j.map_or("n/a".to_string(), |w| format!("{:.3} mJ", w * 1e3)),
        s.passivity.dissipated_j * 1e3,
        mm(Some(s.passivity.drift_max_m)),
        s.packets.forward,
        s.packets.backward
    );
}

/// A physics scene's task: how it ended and what it took.
fn task_line(t: &mut String, task: &crate::task::TaskSummary) {
    let outcome = match (task.success, task.completion_s) {
        (true, Some(c)) => format!("succeeded at {c:.2} s"),
        _ => "did not succeed".to_string(),
    };
    let _ = writeln!(
        t,
        "task: {outcome} (distance to the goal at the end {:.2} mm, closest {:.2} mm); contact force peak {:.3} N, rms {:.3} N; tool path {:.1} mm; the operator's work {:.3} mJ",
        task.final_distance * 1e3,
        task.closest_distance * 1e3,
        task.peak_force_n,
        task.rms_force_n,
        task.path_length_m * 1e3,
        task.operator_energy_j * 1e3
    );
}

/// A URDF arm's tracking in its base frame, and the clutch's releases.
fn task_space(t: &mut String, ts: &crate::task_space::TaskSpace) {
    let mm3 = |v: Option<f64>| v.map_or("n/a".to_string(), |x| format!("{:.3} mm", x * 1e3));
    let deg = |v: Option<f64>| v.map_or("n/a".to_string(), |x| format!("{x:.3} deg"));
    let _ = writeln!(
        t,
        "tracking error (tool against its target after the map, base frame, {} engaged samples): position rms {}, max {}; orientation rms {}, max {}",
        ts.engaged_samples,
        mm3(ts.position_rms_m),
        mm3(ts.position_max_m),
        deg(ts.rotation_rms_deg),
        deg(ts.rotation_max_deg)
    );
    if ts.released_samples > 0 {
        let _ = writeln!(
            t,
            "clutch: released {} samples ({:.3} s), {} engages; released samples are left out of the tracking error: the robot held within {} of its reference",
            ts.released_samples,
            ts.released_s,
            ts.engages,
            mm3(ts.held_max_m)
        );
    }
}

/// What the network and each side counted.
fn counters(t: &mut String, s: &Summary) {
    let m = &s.master;
    if let Some(e) = &s.emulator {
        let c = &e.counters;
        let _ = writeln!(
            t,
            "network forward: {} packets lost, {} samples substituted, {} dropped, {} duplicated, {} corrupted",
            c.forward_packets_lost, c.forward_substituted, c.forward_dropped, c.forward_duplicated, c.forward_corrupted
        );
        let _ = writeln!(
            t,
            "network backward: {} packets lost, {} samples substituted, {} dropped, {} duplicated, {} corrupted",
            c.backward_packets_lost, c.backward_substituted, c.backward_dropped, c.backward_duplicated, c.backward_corrupted
        );
    }
    let mc = &m.totals.counters;
    let _ = writeln!(
        t,
        "master: {} operator targets clamped, {} force clamps, {} torque clamps, {} rejected, {} held, {} peer-lost samples",
        mc.operator_clamped, mc.force_clamps, mc.torque_clamps, mc.rejected, mc.held_samples, mc.peer_lost_samples
    );
    if let Some(sl) = &s.slave {
        let c = &sl.counters;
        let _ = write!(
            t,
            "slave: {} IK targets clamped, {} samples rejected, {} torque clamps, {} holds",
            c.ik_clamped, c.rejected, c.torque_clamps, c.holds
        );
        // Only an arm with a workspace box clamps there: other runs' lines stay.
        if c.workspace_clamped > 0 {
            let _ = write!(
                t,
                ", {} targets clamped to the workspace box",
                c.workspace_clamped
            );
        }
        t.push('\n');
    }
}

/// Real devices over ROS 2, if any.
fn devices(t: &mut String, s: &Summary) {
    let m = &s.master;
    let dev = |t: &mut String, who: &str, d: &tactile_records::device::DeviceCounters| {
        if *d != tactile_records::device::DeviceCounters::default() {
            let _ = writeln!(
                t,
                "{who} over ROS 2: {} messages, {} dropped (malformed, missing joint, not finite, out of range); ticks fresh {}, stale {}, lost {} ({} losses); {} published, {} failed; gate: {} held back, {} limited, {} ramps; {}",
                d.messages, d.rejected, d.fresh, d.stale, d.lost, d.losses, d.published, d.publish_errors,
                d.gated, d.limited, d.ramps,
                if d.released { "released at the end" } else { "NOT released at the end (no subscriber matched)" }
            );
        }
    };
    dev(t, "master device", &m.totals.device);
    if let Some(sl) = &s.slave {
        dev(t, "slave robot", &sl.device);
    }
}

/// Each node's memory, ending, scheduling and damage, and the events.
fn nodes(t: &mut String, s: &Summary) {
    for (role, n) in &s.nodes {
        let _ = writeln!(
            t,
            "node {role}: peak RSS {:.1} MB, {}; {}",
            n.peak_rss_kb as f64 / 1024.0,
            n.ended,
            sched_line(&n.sched)
        );
        if n.damaged_stretches > 0 {
            let at: Vec<String> = n
                .damage
                .iter()
                .map(|[o, b]| format!("{b} at byte {o}"))
                .collect();
            let _ = writeln!(
                t,
                "node {role}: record damaged: {} bytes in {} stretches skipped ({}); every whole frame read",
                n.damaged_bytes,
                n.damaged_stretches,
                at.join(", ")
            );
        }
    }
    for e in &s.events {
        let _ = writeln!(t, "event: {e}");
    }
    if s.events_omitted > 0 {
        let _ = writeln!(t, "({} more events in the records)", s.events_omitted);
    }
}

/// A node's scheduling in one line, with what the kernel refused.
fn sched_line(s: &tactile_records::Sched) -> String {
    let mut t = s.policy.clone();
    if s.priority > 0 {
        t += &format!(" {}", s.priority);
    }
    if let Some(c) = s.cpu {
        t += &format!(", CPU {c}");
    }
    if s.wake_early_us > 0 {
        t += &format!(", wakes {} us early", s.wake_early_us);
    }
    t += &format!(", polls {} us", s.poll_us);
    if s.memory_locked {
        t += ", memory locked";
    }
    if s.idle_poll {
        t += ", CPU kept awake";
    }
    if let Some(n) = &s.note {
        t += &format!(" ({n})");
    }
    t
}
