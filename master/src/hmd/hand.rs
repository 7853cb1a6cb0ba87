//! The hand's side of the master: where the operator means the handle to be at each
//! sample (the path, the approach from home, the person's sway) and where the
//! simulated hand then puts it (ideal or impedance).

use super::Master;
use crate::operator::Target;
use tactile_math::kernels::IkStatus;

impl Master {
    /// What the hand means to do at sample n: the trajectory, blended in from the
    /// devices' home over the approach (both hands, so neither starts with a jump).
    fn target(&mut self, n: u64) -> Target {
        let sway = self.human.as_mut().map(|h| h.step(n, self.last_felt));
        let m = sway.map_or(n, |s| s.progress);
        self.progress = m;
        let a = match &mut self.scripted {
            Some(s) => s.target(m, self.t_s, self.last_felt),
            None => self.source.target(m, self.t_s),
        };
        let a = match &self.approach {
            Some(approach) => approach.apply(a, n as f64 * self.t_s),
            None => a,
        };
        // The person's offsets are in the workspace: a joint target becomes the
        // position it puts the handle at.
        match (sway, a) {
            (None, a) => a,
            (Some(s), Target::Joints(theta)) => {
                let p = self.truth.fk(theta);
                Target::Position([0, 1, 2].map(|k| p[k] + s.offset[k]))
            }
            (Some(s), Target::Position(p)) => {
                Target::Position([0, 1, 2].map(|k| p[k] + s.offset[k]))
            }
        }
    }

    /// Reactions of the simulated operator to a felt force so far.
    pub fn reactions(&self) -> u64 {
        self.human.as_ref().map_or(0, |h| h.reacted)
    }

    /// The impedance hand's intended position at sample n.
    fn intended(&mut self, n: u64) -> [f64; 3] {
        match self.target(n) {
            Target::Joints(theta) => self.truth.fk(theta),
            Target::Position(p) => p,
        }
    }

    /// The impedance hand: the device moves over the sample just ended under the hand
    /// and the torques then applied; the encoders read where it got to.
    pub(super) fn impedance_hand(&mut self, n: u64) -> ([f64; 3], [f64; 3]) {
        let x_d = self.intended(n);
        let (tau, t_s) = (self.last_tau, self.t_s);
        let Some((device, last)) = &mut self.held else {
            return (self.ideal_hand(n), [0.0; 3]);
        };
        if n > 0 {
            device.advance(tau, *last, x_d, t_s);
        }
        *last = x_d;
        self.theta_md = device.theta;
        (x_d, device.hand_force)
    }

    /// The ideal hand: the handle is where the hand means it to be.
    pub(super) fn ideal_hand(&mut self, n: u64) -> [f64; 3] {
        match self.target(n) {
            Target::Joints(theta) => {
                self.theta_md = theta;
                self.truth.fk(theta)
            }
            Target::Position(p) => {
                // The hand puts the handle at p; the encoders read the joint angles the
                // real device takes there (f64: physics, not the HMD datapath).
                let s = self.truth.ik(p);
                match s.status {
                    IkStatus::Reachable => self.theta_md = s.theta,
                    IkStatus::Clamped => {
                        self.counters.operator_clamped += 1;
                        self.theta_md = s.theta;
                    }
                    IkStatus::Invalid => self.counters.operator_clamped += 1,
                }
                p
            }
        }
    }
}
