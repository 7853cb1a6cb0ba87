//! Transparency as researchers publish it: the stiffness the operator felt against the
//! environment's, each identified from the run itself (Lawrence, "Stability and
//! transparency in bilateral teleoperation", IEEE TRA 9(5), 1993: a transparent
//! teleoperator makes the impedance felt equal the environment's).
//!
//! Each is the least-squares spring through the surface (no force there), `k = sum(d f)
//! / sum(d^2)`, so a steady press identifies it as well as a varying one:
//!
//! - The environment's: the contact force's magnitude against the tool's depth behind
//!   the surface, over the slave's steps in contact.
//! - The felt: the felt force along the contact's normal against the handle's depth
//!   behind the same surface, over the master's samples with the handle behind it. A
//!   delayed force that has not come back yet counts as the zero the operator feels (a
//!   wall felt late feels soft), and a slave held short of the handle as the farther
//!   wall it is.
//!
//! The surface and its normal are the slave's latest contact (the nearest surface point
//! and the force's direction): exact for a plane, the tangent plane for a curved
//! object. Sums only, so memory does not grow with the run.
//!
//! With `control.kind = "mmt"` the model's convergence is measured too: from the
//! slave's first step in contact to its first step whose model has the stiffness there
//! within [`CONVERGED_STIFFNESS`] and the surface within [`CONVERGED_SURFACE_M`]. The
//! felt stiffness is then identified again over the master's samples whose force came
//! from then on ("once the model converged").
//!
//! How deep the handle was when the first news of the contact reached the master (the
//! first force from a slave step in contact) is measured for every control: no
//! control can render a wall before it hears of it, so the wall's energy over that
//! depth, `k d^2 / 2`, is work the operator never put in. A control that renders the
//! wall as it is from the news on, with the slave at the handle, leaves the channel
//! short by exactly that at rest (docs/05 derives it); only one that dissipates it at
//! the handle, which the operator feels, can make it up.

use crate::trace::TraceRow;
use serde::Serialize;
use tactile_math::vec3::{distance, dot, norm};
use tactile_messages::samples::Flags;

/// `transparency` in summary.json.
#[derive(Debug, Clone, Copy, Default, PartialEq, Serialize)]
pub struct Transparency {
    /// The stiffness the operator felt, N/m; null without enough contact (see
    /// [`MIN_SAMPLES`] and [`MIN_DEPTH_M`]).
    pub felt_stiffness_n_per_m: Option<f64>,
    /// The environment's stiffness at the tool, N/m; null likewise.
    pub environment_stiffness_n_per_m: Option<f64>,
    /// Felt over environment: 1 is transparent, below 1 feels softer.
    pub stiffness_ratio: Option<f64>,
    /// Master samples with the handle behind the surface.
    pub felt_samples: u64,
    /// Slave steps in contact.
    pub environment_samples: u64,
    /// MMT: from the slave's first contact to its first converged model, ms (null
    /// without a model, or one that never converged).
    pub model_convergence_ms: Option<f64>,
    /// MMT: the felt stiffness over the samples after the model converged, N/m.
    pub felt_stiffness_converged_n_per_m: Option<f64>,
    /// MMT: that over the environment's.
    pub stiffness_ratio_converged: Option<f64>,
    /// MMT: master samples behind the surface after the model converged.
    pub felt_converged_samples: u64,
    /// The handle's depth behind the surface at the first master sample whose force
    /// came from a slave step in contact, m (0 when it was not behind it; null without
    /// contact, or before the news arrived).
    pub unfelt_depth_m: Option<f64>,
    /// The environment's energy over that depth, `k d^2 / 2` with the stiffness
    /// identified over the run, J: what a control that renders the wall where it is leaves the
    /// channel short at rest (null without both).
    pub unfelt_energy_j: Option<f64>,
}

/// A model has converged when its stiffness is within this fraction of the
/// environment's at the contact ...
pub const CONVERGED_STIFFNESS: f64 = 0.1;
/// ... and its surface within this of the contact's surface point, m.
pub const CONVERGED_SURFACE_M: f64 = 1.0e-3;

/// The unfelt depth is measured against the surface of the first slave step pressing
/// with this much force, N: the first step's force, a hundredth of a newton, points
/// anywhere, and later contacts (a bouncing tool's) may be elsewhere.
pub const FIRM_FORCE_N: f64 = 0.1;

/// Fewest samples a stiffness is identified from.
pub const MIN_SAMPLES: u64 = 100;
/// Least RMS depth a stiffness is identified over, m: a graze is mostly noise.
pub const MIN_DEPTH_M: f64 = 2.0e-4;

/// Least squares of y = k x (a spring, no force at the surface), as sums.
#[derive(Debug, Clone, Copy, Default)]
struct Fit {
    n: u64,
    sxx: f64,
    sxy: f64,
}

impl Fit {
    fn add(&mut self, x: f64, y: f64) {
        if x.is_finite() && y.is_finite() {
            self.n += 1;
            self.sxx += x * x;
            self.sxy += x * y;
        }
    }

    fn slope(&self) -> Option<f64> {
        let deep_enough = self.sxx >= self.n as f64 * MIN_DEPTH_M * MIN_DEPTH_M;
        (self.n >= MIN_SAMPLES && deep_enough).then(|| self.sxy / self.sxx)
    }
}

/// The running sums.
#[derive(Debug, Clone, Default)]
pub struct Felt {
    felt: Fit,
    environment: Fit,
    /// The latest contact's surface point and outward normal.
    surface: Option<([f64; 3], [f64; 3])>,
    /// The slave's first step in contact, and its first with a converged model.
    first_contact: Option<u64>,
    converged: Option<u64>,
    felt_converged: Fit,
    /// The handle where it was when the first news of the contact arrived.
    news_handle: Option<[f64; 3]>,
    /// The first firm contact's surface point and normal (see [`FIRM_FORCE_N`]).
    first_surface: Option<([f64; 3], [f64; 3])>,
    /// A URDF arm's clutch: where its offset puts the tool relative to the handle (m,
    /// the master's frame), and whether it is released.
    clutch: ([f64; 3], bool),
}

impl Felt {
    /// The arm's clutch as of the next rows: `shift` is where its offset puts the
    /// tool relative to the handle, m in the master's frame (the handle at `x` meets
    /// the surfaces at `x + shift`); while `released` the operator feels the clutch's
    /// spring, not the wall, and the felt fit leaves the samples out. Both are the
    /// slave's record's: the master's release reaches it a forward delay later, while
    /// the handle is leaving the wall.
    pub fn clutch(&mut self, shift: [f64; 3], released: bool) {
        self.clutch = (shift, released);
    }

    /// Adds one row (rows come in sample order).
    pub fn add(&mut self, row: &TraceRow) {
        let force = norm(row.h);
        if row.stepped && row.contact_object >= 0 && force > 1e-9 {
            self.surface = Some((row.surface, row.h.map(|v| v / force)));
            if force >= FIRM_FORCE_N {
                self.first_surface = self.first_surface.or(self.surface);
            }
            let depth = distance(row.surface, row.tool);
            self.environment.add(depth, force);
            self.first_contact.get_or_insert(row.n);
            if self.converged.is_none() && converged(row, depth, force, self.clutch.0) {
                self.converged = Some(row.n);
            }
        }
        let (shift, released) = self.clutch;
        let felt_ok = row.received
            && !released
            && !row.flags_m.intersects(Flags::REJECTED)
            && !row.flags_b.intersects(Flags::CORRUPTED);
        if let (true, Some(surface)) = (felt_ok, self.surface) {
            let n = surface.1;
            let handle = [0, 1, 2].map(|i| row.handle[i] + shift[i]);
            let depth = behind(surface, handle);
            let from = row.q_from.iter().copied().min().unwrap_or(0);
            if self.news_handle.is_none() && self.first_contact.is_some_and(|c| from >= c) {
                self.news_handle = Some(handle);
            }
            if depth > 0.0 {
                self.felt.add(depth, dot(row.felt, n));
                // The force came from a slave step after the model converged.
                if self.converged.is_some_and(|c| from >= c) {
                    self.felt_converged.add(depth, dot(row.felt, n));
                }
            }
        }
    }

    /// The figures, for a run sampled every `t_s` seconds.
    pub fn finish(&self, t_s: f64) -> Transparency {
        let felt = self.felt.slope();
        let environment = self.environment.slope();
        let converged = self.felt_converged.slope();
        let unfelt = self
            .news_handle
            .zip(self.first_surface)
            .map(|(h, surface)| behind(surface, h).max(0.0));
        let ratio = |f: Option<f64>| match (f, environment) {
            (Some(f), Some(e)) if e > 0.0 => Some(f / e),
            _ => None,
        };
        Transparency {
            felt_stiffness_n_per_m: felt,
            environment_stiffness_n_per_m: environment,
            stiffness_ratio: ratio(felt),
            felt_samples: self.felt.n,
            environment_samples: self.environment.n,
            model_convergence_ms: self
                .first_contact
                .zip(self.converged)
                .map(|(a, b)| b.saturating_sub(a) as f64 * t_s * 1e3),
            felt_stiffness_converged_n_per_m: converged,
            stiffness_ratio_converged: ratio(converged),
            felt_converged_samples: self.felt_converged.n,
            unfelt_depth_m: unfelt,
            unfelt_energy_j: unfelt.zip(environment).map(|(d, k)| 0.5 * k * d * d),
        }
    }
}

/// How far `x` is behind a surface (its point and outward normal), m: negative in
/// front of it.
fn behind((p, n): ([f64; 3], [f64; 3]), x: [f64; 3]) -> f64 {
    dot([0, 1, 2].map(|i| p[i] - x[i]), n)
}

/// Whether the model a contact step carried matches the wall there: its stiffness
/// against the force over the depth (the wall's spring at this point), its surface
/// against the surface point, along the model's normal. The model is the handle's
/// (sent less the clutch's `shift`), the surface point the tool's. A graze (depth
/// under [`MIN_DEPTH_M`]) says nothing.
fn converged(row: &TraceRow, depth: f64, force: f64, shift: [f64; 3]) -> bool {
    if row.model_seq == 0 || depth < MIN_DEPTH_M {
        return false;
    }
    let k = force / depth;
    (row.model_k - k).abs() <= CONVERGED_STIFFNESS * k
        && (row.model_offset + dot(row.model_normal, shift) - dot(row.model_normal, row.surface))
            .abs()
            <= CONVERGED_SURFACE_M
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A wall at z = -0.06 (normal +z) of stiffness `k`; the handle at `handle_z`, the
    /// tool at `tool_z`, the felt force `felt_z`.
    fn row(n: u64, tool_z: f64, handle_z: f64, k: f64, felt_z: f64) -> TraceRow {
        let depth = (-0.06 - tool_z).max(0.0);
        TraceRow {
            n,
            stepped: true,
            received: true,
            contact_object: if depth > 0.0 { 0 } else { -1 },
            tool: [0.0, 0.0, tool_z],
            surface: [0.0, 0.0, -0.06],
            h: [0.0, 0.0, k * depth],
            handle: [0.0, 0.0, handle_z],
            felt: [0.0, 0.0, felt_z],
            ..TraceRow::default()
        }
    }

    fn press(k: f64, felt: impl Fn(f64) -> f64) -> Transparency {
        let mut f = Felt::default();
        for n in 0..2000 {
            // In and out between 1 and 9 mm deep.
            let z = -0.065 - 0.004 * (n as f64 * 0.01).sin();
            f.add(&row(n, z, z, k, felt(-0.06 - z)));
        }
        f.finish(1e-3)
    }

    /// MMT: contact from sample 500, no model for its first 50 steps, then one at 450
    /// N/m (25 % soft), then the wall's own from step 80 of contact; the force comes
    /// back 10 samples late, and the master feels 200 N/m until the wall's model is
    /// back, 600 N/m after.
    #[test]
    fn the_model_converges_when_it_matches_the_wall_and_the_felt_is_fitted_after() {
        let mut f = Felt::default();
        for n in 0..3000u64 {
            let z = match n {
                0..500 => -0.05,
                _ => -0.065 - 0.003 * (n as f64 * 0.01).sin(),
            };
            let mut r = row(n, z, z, 600.0, 0.0);
            let k = match n {
                580.. => 600.0,
                550.. => 450.0,
                _ => 0.0,
            };
            if k > 0.0 {
                (r.model_seq, r.model_normal, r.model_offset, r.model_k) =
                    (1, [0.0, 0.0, 1.0], -0.06, k);
            }
            r.q_from = [n.saturating_sub(10); 3];
            let felt_k = if n >= 590 { 600.0 } else { 200.0 };
            r.felt = [0.0, 0.0, felt_k * (-0.06 - z).max(0.0)];
            f.add(&r);
        }
        let t = f.finish(1e-3);
        assert!(
            (t.model_convergence_ms.expect("converged") - 80.0).abs() < 1e-9,
            "{t:?}"
        );
        let k = t.felt_stiffness_converged_n_per_m.expect("felt");
        assert!((k - 600.0).abs() < 1e-6, "{t:?}");
        assert!((t.stiffness_ratio_converged.expect("ratio") - 1.0).abs() < 1e-9);
        assert!(t.felt_stiffness_n_per_m.expect("felt") < 600.0);
        assert_eq!(t.felt_converged_samples, 3000 - 590);
    }

    /// The handle enters a 600 N/m wall at 50 mm/s from sample 500 (the tool with it)
    /// and the force comes back 200 samples late: the first step in contact is 501 (at
    /// 500 the tool is on the surface), its news arrives at 701 with the handle 201
    /// samples, 10.05 mm, deep: 30.3 mJ of wall unfelt.
    #[test]
    fn the_depth_entered_before_the_first_news_is_measured() {
        let mut f = Felt::default();
        for n in 0..3000u64 {
            let z = -0.06 - 0.05e-3 * (n as f64 - 500.0).clamp(-100.0, 400.0);
            let mut r = row(n, z, z, 600.0, 0.0);
            r.received = n >= 200;
            r.q_from = [n.saturating_sub(200); 3];
            if n == 501 {
                // The first step's force, as on a real run, a hundredth of a newton
                // pointing into the wall.
                r.h = [0.0, 0.0, -0.01];
            }
            f.add(&r);
        }
        // A last contact pushed sideways (6 N at 10 mm, the wall's spring) does not move
        // the surface the depth was measured on.
        let mut r = row(3000, -0.07, -0.07, 600.0, 0.0);
        r.h = [3.6, 0.0, 4.8];
        f.add(&r);
        let t = f.finish(1e-3);
        let d = t.unfelt_depth_m.expect("news arrived");
        assert!((d - 10.05e-3).abs() < 1e-12, "{t:?}");
        let e = t.unfelt_energy_j.expect("energy");
        assert!(
            (e - 0.5 * 600.0 * 10.05e-3 * 10.05e-3).abs() < 1e-9,
            "{t:?}"
        );
        // Without contact there is no news, and no depth.
        let mut f = Felt::default();
        f.add(&row(0, -0.05, -0.07, 600.0, 0.0));
        assert_eq!(f.finish(1e-3).unfelt_depth_m, None);
    }

    /// A URDF arm re-clutched so that the tool is 20 cm below where the handle maps:
    /// measured from the handle plus that shift, the wall is felt as it is and the
    /// handle's model matches it; released samples (the clutch's spring felt instead)
    /// are left out.
    #[test]
    fn a_clutchs_offset_is_added_to_the_handle_and_releases_left_out() {
        let mut f = Felt::default();
        f.clutch([0.0, 0.0, -0.2], false);
        for n in 0..2000 {
            let z = -0.065 - 0.004 * (n as f64 * 0.01).sin();
            let mut r = row(n, z, z + 0.2, 600.0, 600.0 * (-0.06 - z));
            if n >= 100 {
                // The model as the slave sends it: the wall where the handle meets it.
                (r.model_seq, r.model_normal, r.model_offset, r.model_k) =
                    (1, [0.0, 0.0, 1.0], -0.06 + 0.2, 600.0);
            }
            f.add(&r);
        }
        f.clutch([0.0, 0.0, -0.2], true);
        for n in 2000..3000 {
            f.add(&row(n, -0.07, 0.1, 600.0, 9.0));
        }
        let t = f.finish(1e-3);
        assert_eq!(t.felt_samples, 2000, "{t:?}");
        let ratio = t.stiffness_ratio.expect("ratio");
        assert!((ratio - 1.0).abs() < 1e-9, "{t:?}");
        assert_eq!(t.model_convergence_ms, Some(100.0), "{t:?}");
    }

    /// No model, or one that never matches: no convergence, no fit after it.
    #[test]
    fn without_a_matching_model_nothing_converges() {
        let t = press(600.0, |d| 600.0 * d);
        assert_eq!(t.model_convergence_ms, None);
        assert_eq!(t.felt_stiffness_converged_n_per_m, None);
        assert_eq!(t.felt_converged_samples, 0);
    }

    #[test]
    fn a_transparent_loop_feels_the_walls_stiffness() {
        let t = press(600.0, |d| 600.0 * d);
        let felt = t.felt_stiffness_n_per_m.expect("felt");
        let env = t.environment_stiffness_n_per_m.expect("environment");
        assert!(
            (felt - 600.0).abs() < 1e-6 && (env - 600.0).abs() < 1e-6,
            "{t:?}"
        );
        assert!((t.stiffness_ratio.expect("ratio") - 1.0).abs() < 1e-9);
        assert_eq!((t.felt_samples, t.environment_samples), (2000, 2000));
    }

    #[test]
    fn a_softer_rendering_is_a_ratio_below_one() {
        // Felt through a 1.6 kN/m position controller in series with the wall.
        let series = 1.0 / (1.0 / 600.0 + 1.0 / 1600.0);
        let t = press(600.0, |d| series * d);
        assert!(
            (t.stiffness_ratio.expect("ratio") - series / 600.0).abs() < 1e-9,
            "{t:?}"
        );
    }

    /// The slave held 5 mm short of a handle 10 mm deep: 3 N felt at 10 mm.
    #[test]
    fn a_still_hold_short_of_the_handle_feels_softer() {
        let mut f = Felt::default();
        for n in 0..5000 {
            f.add(&row(n, -0.065, -0.07, 600.0, 3.0));
        }
        let t = f.finish(1e-3);
        assert_eq!((t.felt_samples, t.environment_samples), (5000, 5000));
        assert!(
            (t.felt_stiffness_n_per_m.expect("felt") - 300.0).abs() < 1e-6,
            "{t:?}"
        );
        assert!((t.stiffness_ratio.expect("ratio") - 0.5).abs() < 1e-9);
    }

    #[test]
    fn no_contact_or_a_graze_identifies_nothing() {
        let mut f = Felt::default();
        for n in 0..5000 {
            f.add(&row(n, -0.05, -0.05, 600.0, 0.0));
        }
        assert_eq!(f.finish(1e-3), Transparency::default());
        for n in 0..5000 {
            f.add(&row(n, -0.0601, -0.0601, 600.0, 0.06));
        }
        let t = f.finish(1e-3);
        assert_eq!(t.felt_samples, 5000);
        assert_eq!(t.felt_stiffness_n_per_m, None, "0.1 mm deep: {t:?}");
    }

    #[test]
    fn rejected_or_corrupted_answers_are_left_out() {
        let mut f = Felt::default();
        let mut r = row(0, -0.07, -0.07, 600.0, 1e6);
        r.flags_m = Flags::REJECTED;
        f.add(&r);
        r.flags_m = Flags::NONE;
        r.flags_b = Flags::CORRUPTED;
        f.add(&r);
        assert_eq!(f.finish(1e-3).felt_samples, 0);
    }
}
