//! What a loop does with a device's judgements ([`crate::watch`]): the angles it
//! holds through staleness and loss and the events it records, and the once-a-second
//! log line. Shared by the master and the slave.

use crate::{Change, Reading};

/// A device's angles as a loop holds them: the last good ones (held while the device
/// is stale or lost) and whether it is lost now. `V`: three angles, or an arm's
/// joints.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct Held<V = [f64; 3]> {
    /// The last fresh or stale angles, rad.
    pub theta: V,
    /// True while the device is lost.
    pub lost: bool,
    /// True once a fresh or stale reading was taken (`theta` is the device's, not the
    /// default).
    pub taken: bool,
}

impl<V> Held<V> {
    /// Takes a tick's judgement of `who` (a `kind`: device, robot). Returns the
    /// record's event when it was just lost (also logged as a warning; `meanwhile`
    /// says what the loop does then) or is back.
    pub fn take(
        &mut self,
        (reading, change): (Reading<V>, Change),
        (kind, who): (&str, &str),
        meanwhile: &str,
    ) -> Option<String> {
        self.lost = matches!(reading, Reading::Lost);
        match reading {
            Reading::Fresh(t) | Reading::Stale(t) => {
                self.theta = t;
                self.taken = true;
            }
            Reading::Lost => {}
        }
        match change {
            Change::Lost => {
                let what = format!("{kind} lost: {who} silent past its timeout; {meanwhile}");
                tracing::warn!("{what}");
                Some(what)
            }
            Change::Back => Some(format!("{kind} back: {who}")),
            Change::None => None,
        }
    }
}

pub use tactile_peripheral::log_second;

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn held_angles_stay_through_a_loss_and_the_record_hears_of_it() {
        let mut h = Held::default();
        let t = [0.1, 0.2, 0.3];
        let who = ("device", "the device on /js");
        assert_eq!(h.take((Reading::Fresh(t), Change::None), who, "x"), None);
        let lost = h.take((Reading::Lost, Change::Lost), who, "zero force");
        assert_eq!(
            lost.as_deref(),
            Some("device lost: the device on /js silent past its timeout; zero force")
        );
        assert_eq!(
            h,
            Held {
                theta: t,
                lost: true,
                taken: true,
            }
        );
        let back = h.take((Reading::Stale(t), Change::Back), who, "x");
        assert_eq!(back.as_deref(), Some("device back: the device on /js"));
        assert!(!h.lost);
    }
}
