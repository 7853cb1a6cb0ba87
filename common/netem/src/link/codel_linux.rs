//! CoDel as Linux's `include/net/codel_impl.h` computes it, through ns-3's port
//! (`src/traffic-control/model/codel-queue-disc.cc`, ns-3.37), step for step: the
//! same state machine as RFC 8289 with its integer arithmetic (times in 1024 ns units
//! truncated to 32 bits, so they wrap after 73 minutes as ns-3's do; `1/sqrt(count)`
//! by one Newton step per count in 16-bit fixed point), and ns-3's comparisons (a
//! strict `now > first_above`, no drop while `bytes < mtu`, an empty queue leaving
//! `first_above` as it was). It exists so the ns-3 check can ask for the same drops
//! packet for packet; [`super::codel`]'s RFC arithmetic is the default.

use super::codel::{CodelParams, CodelState};
use super::queue::{DropCause, Packet, Sub};

/// Linux's `CODEL_SHIFT`: time units of 1024 ns.
const SHIFT: u32 = 10;

fn units(ns: u64) -> u32 {
    (ns >> SHIFT) as u32
}

fn after(a: u32, b: u32) -> bool {
    i64::from(a) - i64::from(b) > 0
}

fn after_eq(a: u32, b: u32) -> bool {
    i64::from(a) - i64::from(b) >= 0
}

fn before(a: u32, b: u32) -> bool {
    i64::from(a) - i64::from(b) < 0
}

/// Linux's `codel_Newton_step`: `1/sqrt(count)` refined once.
fn newton_step(rec: u16, count: u32) -> u16 {
    let invsqrt = u64::from(u32::from(rec) << 16);
    let invsqrt2 = (invsqrt * invsqrt) >> 32;
    let mut val = (3u64 << 32).wrapping_sub(u64::from(count) * invsqrt2);
    val >>= 2;
    val = (val.wrapping_mul(invsqrt)) >> (32 - 2 + 1);
    (val >> 16) as u16
}

/// Linux's `codel_control_law`: `t + interval * rec_inv_sqrt`.
fn control_law(t: u32, interval: u32, rec: u16) -> u32 {
    let r = u64::from(u32::from(rec) << 16);
    t.wrapping_add(((u64::from(interval) * r) >> 32) as u32)
}

impl CodelState {
    /// ns-3's `OkToDrop` for the head just taken (`None`: the queue was empty).
    fn ok_to_drop(
        &mut self,
        c: &CodelParams,
        q: &Sub,
        p: Option<Packet>,
        now: u32,
        at: u64,
    ) -> bool {
        let Some(p) = p else {
            self.first_above = 0;
            return false;
        };
        let sojourn = units(at.saturating_sub(p.arrival_ns));
        if before(sojourn, units(c.target_ns)) || q.bytes < u64::from(c.mtu_bytes) {
            self.first_above = 0;
            return false;
        }
        if self.first_above == 0 {
            self.first_above = u64::from(now.wrapping_add(units(c.interval_ns)));
            return false;
        }
        after(now, self.first_above as u32)
    }

    /// ns-3's `DoDequeue`.
    pub(super) fn dequeue_linux(
        &mut self,
        c: &CodelParams,
        q: &mut Sub,
        at: u64,
        drops: &mut Vec<(Packet, DropCause)>,
    ) -> Option<Packet> {
        let Some(head) = q.pop() else {
            self.dropping = false;
            return None;
        };
        let now = units(at);
        let interval = units(c.interval_ns);
        let mut p = Some(head);
        let ok = self.ok_to_drop(c, q, p, now, at);
        if self.dropping {
            if !ok {
                self.dropping = false;
            } else {
                while self.dropping && after_eq(now, self.drop_next as u32) {
                    self.count = self.count.wrapping_add(1);
                    self.rec_inv_sqrt = newton_step(self.rec_inv_sqrt, self.count);
                    if let Some(d) = p {
                        drops.push((d, DropCause::Aqm));
                    }
                    p = q.pop();
                    if self.ok_to_drop(c, q, p, now, at) {
                        let next = control_law(self.drop_next as u32, interval, self.rec_inv_sqrt);
                        self.drop_next = u64::from(next);
                    } else {
                        self.dropping = false;
                    }
                }
            }
        } else if ok {
            if let Some(d) = p {
                drops.push((d, DropCause::Aqm));
            }
            p = q.pop();
            self.ok_to_drop(c, q, p, now, at);
            self.dropping = true;
            let delta = self.count.wrapping_sub(self.lastcount) as i32;
            let since = now.wrapping_sub(self.drop_next as u32);
            if delta > 1 && before(since, interval.wrapping_mul(16)) {
                self.count = delta as u32;
                self.rec_inv_sqrt = newton_step(self.rec_inv_sqrt, self.count);
            } else {
                self.count = 1;
                self.rec_inv_sqrt = u16::MAX;
            }
            self.lastcount = self.count;
            self.drop_next = u64::from(control_law(now, interval, self.rec_inv_sqrt));
        }
        p
    }
}
