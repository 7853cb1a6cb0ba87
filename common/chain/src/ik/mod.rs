//! Inverse kinematics for any chain, one call per sampling period: damped least
//! squares (Wampler 1986) whose damping rises only near a singularity (Maciejewski and
//! Klein 1988: zero while the smallest singular value of the weighted Jacobian is
//! above a threshold, up to `damping_max` as it falls to zero), joint limits clamped,
//! the step scaled down so that no joint moves faster than its velocity limit, and a
//! posture term in the task's null space for redundant arms. A call never jumps: its
//! result is at most one period's travel from where the arm is.
//!
//! [`Ik`] is the model (the chain, the configuration, the counters), [`Workspace`] the
//! data a call works in (Pinocchio's `Model` and `Data`, as [`crate::Dynamics`] and its
//! workspace): [`Ik::step_into`] with a workspace made once allocates nothing, so a
//! slave calls it every sample; [`Ik::step`] makes both for one call.

use crate::chain::Chain;
use crate::error::Error;
use crate::spatial::{log_rotation, Frame};

mod solve;

pub use solve::Workspace;

/// The middle of a joint's limits, the default posture (0 where a limit is
/// infinite). Halved before the sum: `(lower + upper) / 2` overflows to infinity for
/// finite limits above about 9e307, which a URDF may hold.
fn midpoint(lower: f64, upper: f64) -> f64 {
    if lower.is_finite() && upper.is_finite() {
        lower / 2.0 + upper / 2.0
    } else {
        0.0
    }
}

/// A target: the tip's pose in the base frame.
pub type Pose = Frame;

/// How the IK solves.
#[derive(Debug, Clone, PartialEq)]
pub struct IkConfig {
    /// Newton steps per call at most.
    pub max_iterations: usize,
    /// Position error a call stops at, m.
    pub tolerance_m: f64,
    /// Orientation error a call stops at, rad.
    pub tolerance_rad: f64,
    /// Metres an orientation error of one radian weighs against a position error.
    pub orientation_weight: f64,
    /// Whether only the position is followed (an arm of three joints).
    pub position_only: bool,
    /// The largest damping, reached at a singularity (weighted units, m).
    pub damping_max: f64,
    /// The smallest singular value below which damping starts (weighted units, m).
    pub singular_threshold: f64,
    /// The rest posture the null-space term pulls toward; the middle of each joint's
    /// range (0 for a continuous joint) when not given.
    pub posture: Option<Vec<f64>>,
    /// Fraction of the gap to the posture closed per call, within the null space.
    pub posture_gain: f64,
    /// Fraction of each URDF velocity limit a call may use.
    pub velocity_scale: f64,
    /// Position error left after a call, not explained by the velocity limit, from
    /// which the target counts as unreachable, m.
    pub unreachable_m: f64,
    /// The same for the orientation, rad.
    pub unreachable_rad: f64,
}

impl Default for IkConfig {
    fn default() -> IkConfig {
        IkConfig {
            max_iterations: 4,
            tolerance_m: 1e-6,
            tolerance_rad: 1e-5,
            orientation_weight: 0.1,
            position_only: false,
            damping_max: 0.04,
            singular_threshold: 0.02,
            posture: None,
            posture_gain: 0.02,
            velocity_scale: 1.0,
            unreachable_m: 1e-3,
            unreachable_rad: 1e-2,
        }
    }
}

/// What one call did (the joint values to command are the caller's: see
/// [`Ik::step_into`]).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct IkStep {
    /// Position error left at the command, m.
    pub position_error: f64,
    /// Orientation error left at the command, rad (0 when only the position is
    /// followed).
    pub orientation_error: f64,
    /// Newton steps taken.
    pub iterations: usize,
    /// Whether a joint limit clamped the solution.
    pub clamped: bool,
    /// Whether the velocity limit shortened the step.
    pub velocity_limited: bool,
    /// Whether the target is out of reach (error left, and not for speed).
    pub unreachable: bool,
    /// The largest damping used, m.
    pub damping: f64,
}

/// Counters over every call.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct IkStats {
    /// Calls.
    pub calls: u64,
    /// Newton steps.
    pub iterations: u64,
    /// Calls a joint limit clamped.
    pub clamped: u64,
    /// Calls the velocity limit shortened.
    pub velocity_limited: u64,
    /// Calls whose target was out of reach.
    pub unreachable: u64,
    /// Calls that damped (near a singularity).
    pub damped: u64,
}

/// The IK of one chain, with its counters.
#[derive(Debug, Clone)]
pub struct Ik {
    chain: Chain,
    config: IkConfig,
    posture: Vec<f64>,
    /// Counters over every call.
    pub stats: IkStats,
}

fn bad(field: &str, problem: String) -> Error {
    Error::Field {
        at: "ik".into(),
        field: field.into(),
        problem,
    }
}

impl Ik {
    /// The IK of `chain`; the configuration checked.
    pub fn new(chain: &Chain, config: IkConfig) -> Result<Ik, Error> {
        let positive = [
            ("tolerance_m", config.tolerance_m),
            ("tolerance_rad", config.tolerance_rad),
            ("orientation_weight", config.orientation_weight),
            ("singular_threshold", config.singular_threshold),
            ("velocity_scale", config.velocity_scale),
            ("unreachable_m", config.unreachable_m),
            ("unreachable_rad", config.unreachable_rad),
        ];
        for (name, v) in positive {
            if !(v.is_finite() && v > 0.0) {
                return Err(bad(name, format!("{v} must be a positive number")));
            }
        }
        for (name, v) in [
            ("damping_max", config.damping_max),
            ("posture_gain", config.posture_gain),
        ] {
            if !(v.is_finite() && (0.0..=1.0).contains(&v)) {
                return Err(bad(name, format!("{v} must be within 0..=1")));
            }
        }
        if config.max_iterations == 0 || config.max_iterations > 100 {
            return Err(bad(
                "max_iterations",
                format!("{} must be within 1..=100", config.max_iterations),
            ));
        }
        let posture = match &config.posture {
            Some(p) => {
                chain.check_len("ik posture", p)?;
                p.clone()
            }
            None => chain
                .dofs
                .iter()
                .map(|d| midpoint(d.lower, d.upper))
                .collect(),
        };
        Ok(Ik {
            chain: chain.clone(),
            config,
            posture,
            stats: IkStats::default(),
        })
    }

    /// The chain.
    pub fn chain(&self) -> &Chain {
        &self.chain
    }

    /// The task rows followed: 6, or 3 for a position.
    fn rows(&self) -> usize {
        if self.config.position_only {
            3
        } else {
            6
        }
    }

    /// The errors left at `tip`: position (m), orientation (rad), and the weighted
    /// error vector (its first [`Ik::rows`] entries are the task's).
    fn error(&self, tip: &Frame, target: &Pose) -> (f64, f64, [f64; 6]) {
        let ep = target.p - tip.p;
        let er = log_rotation(&(target.r * tip.r.transpose()));
        let w = self.config.orientation_weight;
        let e = [ep.x, ep.y, ep.z, w * er.x, w * er.y, w * er.z];
        let rot = if self.config.position_only {
            0.0
        } else {
            er.norm()
        };
        (ep.norm(), rot, e)
    }

    /// One period's command toward `target` from the arm at `q_now`, for a period of
    /// `dt` seconds: the joint values to command, and what the call did. Makes a
    /// workspace and the result for the one call; a loop calls [`Ik::step_into`].
    pub fn step(
        &mut self,
        q_now: &[f64],
        target: &Pose,
        dt: f64,
    ) -> Result<(Vec<f64>, IkStep), Error> {
        let mut q = vec![0.0; q_now.len()];
        let step = self.step_into(&mut Workspace::new(self), q_now, target, dt, &mut q)?;
        Ok((q, step))
    }

    /// [`Ik::step`] with the command written into `q` (one value per degree of
    /// freedom, untouched on an error) and its scratch in `ws`: no allocation once `ws`
    /// fits this IK (as [`Workspace::new`] makes it; one that served another grows on
    /// its first call here).
    pub fn step_into(
        &mut self,
        ws: &mut Workspace,
        q_now: &[f64],
        target: &Pose,
        dt: f64,
        q: &mut [f64],
    ) -> Result<IkStep, Error> {
        self.chain.check_len("ik q", q_now)?;
        if !(dt.is_finite() && dt > 0.0) || q_now.iter().any(|x| !x.is_finite()) {
            return Err(bad(
                "step",
                "the joint values and the period must be finite".into(),
            ));
        }
        self.chain.check_len("ik command", q)?;
        ws.fit(self);
        ws.start.copy_from_slice(q_now);
        let mut clamped = self.chain.clamp(&mut ws.start) > 0;
        q.copy_from_slice(&ws.start);
        let (mut iterations, mut damping) = (0, 0.0f64);
        for it in 0..self.config.max_iterations {
            ws.before.copy_from_slice(q);
            match self.iterate(ws, q, target, it == 0) {
                Some((_, c, true)) => {
                    clamped |= c;
                    break;
                }
                Some((lambda, c, false)) => {
                    iterations += 1;
                    damping = damping.max(lambda);
                    clamped |= c;
                }
                // Nothing non-finite leaves: the arm holds where the last step left it.
                None => {
                    q.copy_from_slice(&ws.before);
                    break;
                }
            }
        }
        // Out of reach: even unhurried, the solution leaves an error and gains little
        // on where the arm stands.
        let (ep0, er0, _) = self.error(&self.chain.fk(&ws.start), target);
        let (ep1, er1, _) = self.error(&self.chain.fk(q), target);
        let (cm, cr) = (self.config.unreachable_m, self.config.unreachable_rad);
        let unreachable = (ep1 > cm && ep1 > 0.9 * ep0) || (er1 > cr && er1 > 0.9 * er0);
        let velocity_limited = self.limit_speed(&ws.start, q, dt);
        let (position_error, orientation_error, _) = self.error(&self.chain.fk(q), target);
        let s = &mut self.stats;
        s.calls += 1;
        s.iterations += iterations as u64;
        s.clamped += u64::from(clamped);
        s.velocity_limited += u64::from(velocity_limited);
        s.unreachable += u64::from(unreachable);
        s.damped += u64::from(damping > 0.0);
        Ok(IkStep {
            position_error,
            orientation_error,
            iterations,
            clamped,
            velocity_limited,
            unreachable,
            damping,
        })
    }

    /// Scales the move from `start` to `q` so that no joint exceeds its velocity
    /// limit over `dt`: the same fraction for every joint, so the direction stays.
    fn limit_speed(&self, start: &[f64], q: &mut [f64], dt: f64) -> bool {
        let over = self
            .chain
            .dofs
            .iter()
            .zip(start.iter().zip(q.iter()))
            .map(|(d, (a, b))| (b - a).abs() / (d.velocity * self.config.velocity_scale * dt))
            .fold(0.0f64, f64::max);
        if over <= 1.0 {
            return false;
        }
        for (x, a) in q.iter_mut().zip(start) {
            *x = a + (*x - a) / over;
        }
        true
    }
}

#[cfg(test)]
mod tests {
    use super::midpoint;

    /// Huge finite limits have a finite middle: `(lower + upper) / 2` was infinity.
    #[test]
    fn huge_limits_have_a_finite_middle() {
        assert_eq!(midpoint(1e308, 1.5e308), 1.25e308);
        assert_eq!(midpoint(-1.7e308, 1.7e308), 0.0);
        assert_eq!(midpoint(-1.0, 3.0), 1.0);
        assert_eq!(midpoint(f64::NEG_INFINITY, 1.0), 0.0);
    }
}
