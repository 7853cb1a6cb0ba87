//! Packet loss with netem's models: random loss, Gilbert-Elliott (`gemodel p r 1-h
//! 1-k`) and the 4-state Markov model (`state p13 p31 p32 p23 p14`), with the
//! closed-form long-run loss rate each is checked against.

use rand::Rng;
use tactile_scenario::LossModel;

/// The long-run loss rate (the stationary probability of the losing states).
pub fn loss_rate(model: &LossModel) -> f64 {
    match *model {
        LossModel::Gemodel {
            p,
            r,
            bad_loss,
            good_loss,
        } => {
            if p + r == 0.0 {
                return good_loss;
            }
            let bad = p / (p + r);
            (1.0 - bad) * good_loss + bad * bad_loss
        }
        LossModel::State {
            p13,
            p31,
            p32,
            p23,
            p14,
        } => {
            // Balance: pi4 = p14 pi1; pi3 (p31 + p32) = p13 pi1 + p23 pi2;
            // pi2 p23 = p32 pi3. With p23 > 0: pi3 p31 = p13 pi1.
            let s = StateChain::stationary(p13, p31, p32, p23, p14);
            s[2] + s[3]
        }
    }
}

/// The stationary distribution of the 4-state chain.
pub(crate) struct StateChain;

impl StateChain {
    /// The long-run share of each state, starting from state 1 (for a chain that is
    /// not irreducible, the class the chain ends up in from there).
    pub(crate) fn stationary(p13: f64, p31: f64, p32: f64, p23: f64, p14: f64) -> [f64; 4] {
        // Never leaving {1, 4}: pi4 = p14 pi1.
        if p13 == 0.0 {
            return [1.0 / (1.0 + p14), 0.0, 0.0, p14 / (1.0 + p14)];
        }
        // Once in {2, 3} for good (no way back to 1): the 2-3 chain alone.
        if p31 == 0.0 {
            return match (p32 > 0.0, p23 > 0.0) {
                (true, true) => [0.0, p23 / (p23 + p32), p32 / (p23 + p32), 0.0],
                (true, false) => [0.0, 1.0, 0.0, 0.0],
                _ => [0.0, 0.0, 1.0, 0.0],
            };
        }
        // State 2 absorbing once reached.
        if p32 > 0.0 && p23 == 0.0 {
            return [0.0, 1.0, 0.0, 0.0];
        }
        // Relative to pi1 = 1: pi4 = p14; pi3 = p13 / p31 (the flows between {1, 4}
        // and {2, 3} balance, and only 1 -> 3 and 3 -> 1 cross); pi2 = p32 pi3 / p23.
        let pi3 = p13 / p31;
        let pi2 = if p23 > 0.0 { p32 * pi3 / p23 } else { 0.0 };
        let total = 1.0 + p14 + pi3 + pi2;
        [1.0 / total, pi2 / total, pi3 / total, p14 / total]
    }
}

/// The state of a loss model.
#[derive(Debug, Clone)]
pub struct Loss {
    model: LossModel,
    state: u8,
}

impl Loss {
    /// A model in its good state.
    pub fn new(model: &LossModel) -> Self {
        Loss {
            model: model.clone(),
            state: 1,
        }
    }

    /// Whether the next packet is lost; moves the chain one packet on.
    pub fn lose(&mut self, rng: &mut impl Rng) -> bool {
        match self.model {
            LossModel::Gemodel {
                p,
                r,
                bad_loss,
                good_loss,
            } => {
                // The state moves, then the packet's fate is drawn in the state it moved
                // to (netem's loss_gilb_ell draws the fate in the state it leaves; the
                // long-run rates are the same).
                let u: f64 = rng.random();
                self.state = match self.state {
                    1 if u < p => 3,
                    3 if u < r => 1,
                    s => s,
                };
                let loss = if self.state == 3 { bad_loss } else { good_loss };
                loss > 0.0 && rng.random::<f64>() < loss
            }
            LossModel::State {
                p13,
                p31,
                p32,
                p23,
                p14,
            } => {
                let u: f64 = rng.random();
                self.state = match self.state {
                    1 if u < p13 => 3,
                    1 if u < p13 + p14 => 4,
                    2 if u < p23 => 3,
                    3 if u < p31 => 1,
                    3 if u < p31 + p32 => 2,
                    4 => 1,
                    s => s,
                };
                self.state == 3 || self.state == 4
            }
        }
    }
}
