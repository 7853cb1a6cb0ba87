//! CoDel (RFC 8289): a FIFO whose head is dropped at dequeue while packets' sojourn
//! time (`now - arrival_ns`) has stayed above a target for an interval, the drops
//! coming closer as `interval / sqrt(count)` (the control law) until the sojourn falls
//! below the target. The state machine is the RFC's pseudo-code (`dodequeue` and
//! `dequeue`, §5), in ns, the control law in floating point as the RFC writes it.

use super::queue::{Bound, DropCause, Packet, Queue, Sub};

/// CoDel's parameters, RFC 8289's defaults.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct CodelParams {
    /// The acceptable standing sojourn time, ns [5 ms].
    pub target_ns: u64,
    /// The window the sojourn must stay above the target before a drop, ns [100 ms].
    pub interval_ns: u64,
    /// The RFC's `maxpacket_`: no drop while the queue holds at most this many bytes
    /// (one MTU: a slow link's single packet is no standing queue) [1500].
    pub mtu_bytes: u32,
    /// The arithmetic: the RFC's (ns, a square root) or Linux's and ns-3's.
    pub arithmetic: Arithmetic,
}

/// How CoDel computes: RFC 8289's pseudo-code as written, or as Linux's `codel.h`
/// and ns-3's `CoDelQueueDisc` (its port) do ([`super::codel_linux`]): time in
/// units of 1024 ns truncated to 32 bits, `1/sqrt(count)` by one Newton step a drop in
/// 16-bit fixed point, a strict `now > first_above` and `bytes < mtu`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Arithmetic {
    /// RFC 8289's.
    #[default]
    Rfc,
    /// Linux's and ns-3's.
    Linux,
}

impl Default for CodelParams {
    fn default() -> CodelParams {
        CodelParams {
            target_ns: 5_000_000,
            interval_ns: 100_000_000,
            mtu_bytes: 1500,
            arithmetic: Arithmetic::Rfc,
        }
    }
}

/// One queue's CoDel state (the RFC's variables ending in `_`), shared by
/// [`Codel`] and each flow of FQ-CoDel.
/// (Times in ns, or in Linux's 1024 ns units under [`Arithmetic::Linux`].)
#[derive(Debug, Clone, Copy)]
pub(super) struct CodelState {
    /// When the sojourn may first be called above for an interval (0: below).
    pub(super) first_above: u64,
    /// The next drop's time in the dropping state.
    pub(super) drop_next: u64,
    /// Drops since entering the dropping state.
    pub(super) count: u32,
    /// `count` when the dropping state was last entered.
    pub(super) lastcount: u32,
    /// In the dropping state.
    pub(super) dropping: bool,
    /// Linux's `1/sqrt(count)` in 16-bit fixed point.
    pub(super) rec_inv_sqrt: u16,
}

impl Default for CodelState {
    fn default() -> CodelState {
        CodelState {
            first_above: 0,
            drop_next: 0,
            count: 0,
            lastcount: 0,
            dropping: false,
            rec_inv_sqrt: u16::MAX,
        }
    }
}

impl CodelState {
    /// The RFC's `dodequeue`: the head, and whether CoDel may drop it.
    fn dodequeue(&mut self, c: &CodelParams, q: &mut Sub, now: u64) -> (Option<Packet>, bool) {
        let Some(p) = q.pop() else {
            self.first_above = 0;
            return (None, false);
        };
        let sojourn = now.saturating_sub(p.arrival_ns);
        if sojourn < c.target_ns || q.bytes <= u64::from(c.mtu_bytes) {
            self.first_above = 0;
            return (Some(p), false);
        }
        if self.first_above == 0 {
            self.first_above = now + c.interval_ns;
            return (Some(p), false);
        }
        (Some(p), now >= self.first_above)
    }

    /// The RFC's `control_law`: `t + interval / sqrt(count)`.
    fn control_law(c: &CodelParams, t: u64, count: u32) -> u64 {
        t + (c.interval_ns as f64 / f64::from(count.max(1)).sqrt()) as u64
    }

    /// The RFC's `dequeue`: the packet to send from `q` at `now`, the ones dropped on
    /// the way into `drops`.
    pub(super) fn dequeue(
        &mut self,
        c: &CodelParams,
        q: &mut Sub,
        now: u64,
        drops: &mut Vec<(Packet, DropCause)>,
    ) -> Option<Packet> {
        if c.arithmetic == Arithmetic::Linux {
            return self.dequeue_linux(c, q, now, drops);
        }
        let (mut p, mut ok) = self.dodequeue(c, q, now);
        if self.dropping {
            if !ok {
                self.dropping = false;
            }
            while self.dropping && now >= self.drop_next {
                if let Some(d) = p {
                    drops.push((d, DropCause::Aqm));
                }
                self.count = self.count.wrapping_add(1);
                (p, ok) = self.dodequeue(c, q, now);
                if ok {
                    self.drop_next = Self::control_law(c, self.drop_next, self.count);
                } else {
                    self.dropping = false;
                }
            }
        } else if ok {
            if let Some(d) = p {
                drops.push((d, DropCause::Aqm));
            }
            (p, _) = self.dodequeue(c, q, now);
            self.dropping = true;
            // The Linux variant the RFC gives: back near the last cycle's drop rate
            // if the queue went above target soon after it went below.
            let delta = self.count.wrapping_sub(self.lastcount);
            let since = now as i128 - self.drop_next as i128;
            self.count = if delta > 1 && since < 16 * i128::from(c.interval_ns) {
                delta
            } else {
                1
            };
            self.drop_next = Self::control_law(c, now, self.count);
            self.lastcount = self.count;
        }
        p
    }
}

/// CoDel over one FIFO, bounded (drop-tail) by `bound` if set.
#[derive(Debug)]
pub struct Codel {
    q: Sub,
    state: CodelState,
    params: CodelParams,
    bound: Bound,
}

impl Codel {
    /// CoDel with `params`, its queue refusing arrivals past `bound` (none: only the
    /// link's memory cap).
    pub fn new(params: CodelParams, bound: Bound) -> Codel {
        Codel {
            q: Sub::default(),
            state: CodelState::default(),
            params,
            bound,
        }
    }
}

impl Queue for Codel {
    fn enqueue(&mut self, p: Packet, drops: &mut Vec<(Packet, DropCause)>) {
        self.q.push_bounded(p, self.bound, drops);
    }

    fn dequeue(&mut self, now_ns: u64, drops: &mut Vec<(Packet, DropCause)>) -> Option<Packet> {
        self.state.dequeue(&self.params, &mut self.q, now_ns, drops)
    }

    fn len_packets(&self) -> usize {
        self.q.q.len()
    }

    fn len_bytes(&self) -> u64 {
        self.q.bytes
    }
}
