//! Stability control on the channel of a position-force bilateral loop, per Cartesian
//! axis, as pure state machines: [`MasterSide`] turns the handle's position into what
//! is sent and what comes back into the force on the handle; [`SlaveSide`] turns what
//! arrives into the slave's position reference and its force into what is sent back.
//!
//! Every kind keeps the two-port's energy books, so the channel's passivity is watched
//! even with `none`. Port powers, counted as energy leaving the channel:
//! master `f_m . v_m` (the force the channel puts on the handle times the handle's
//! velocity), slave `F_s . v_sd` (the force the slave side resists with times the
//! reference's velocity; F_s = -h, the environment's force on the tool, reversed).
//! Each side books energy in and out per axis, sends its input energy with every sample,
//! and observes `W = E_in(other side, as last received) - E_out(this side)`: the
//! channel has produced energy if W < 0 (Ryu, Artigas and Preusche, "A passive
//! bilateral control scheme for a teleoperator with time-varying communication
//! delay", Mechatronics 20, 2010; Artigas, Ryu, Preusche, Hirzinger, "Network
//! representation and passivity of delayed teleoperation systems", IROS 2011).
//!
//! - `tdpa`: passivity controllers where W < 0. Master (force out to the device)
//!   adds damping `alpha = -W / (T v^2)` against the handle's motion (Ryu and
//!   Hannaford, "Time domain passivity control of haptic interfaces", IEEE TRA 18(1),
//!   2002), with v^2 floored and alpha capped (a deficit it cannot remove at once stays
//!   in W and is removed on later samples). Slave (motion out to the position
//!   controller) slows the reference's velocity, `v' = v + W / (F_s T)`, so the reference
//!   drifts from the master's position; the drift is pulled back only with energy the
//!   observer has to spare (Artigas, Ryu, Preusche, "Position drift compensation in
//!   time domain passivity based teleoperation", IROS 2010).
//! - `wave`: wave variables (Niemeyer and Slotine, "Stable adaptive teleoperation",
//!   IEEE JOE 16(1), 1991; "Telemanipulation with time delays", IJRR 23(9), 2004):
//!   `u = (F + b v)/sqrt(2b)` forward, `w = (F - b v)/sqrt(2b)` back. The slave
//!   terminates the channel in its impedance b (a damper in series: no wave is
//!   reflected in free motion), integrates the velocity into its position reference and
//!   returns `w = F_env / sqrt(2b)`; the master feels `-(b v_m + sqrt(2b) w)`.

use tactile_scenario::{ControlConfig, ControlKind, MmtSlave};

/// Energy that entered and left the channel at one port, per axis, J.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct Ledger {
    /// Energy the port put into the channel.
    pub input: [f64; 3],
    /// Energy the channel put out at the port.
    pub output: [f64; 3],
}

/// The most power a port can plausibly exchange, W: thirty times an Omni-class
/// device's 3.3 N at 1 m/s. An input energy that grows faster than this from one
/// sample to the next is not physical and is not believed.
pub const MAX_POWER_W: f64 = 100.0;

impl Ledger {
    /// Energy put in minus energy put out, all axes, J: this port's share of the
    /// energy inside the channel.
    pub fn net(&self) -> f64 {
        (0..3).map(|i| self.input[i] - self.output[i]).sum()
    }

    /// Books one sample's energy on axis `i`: positive leaves the channel.
    fn book(&mut self, i: usize, out_j: f64) {
        if !out_j.is_finite() {
            return;
        }
        if out_j > 0.0 {
            self.output[i] += out_j;
        } else {
            self.input[i] -= out_j;
        }
    }
}

/// The other side's input energy as last believed: it only grows, so a value that is
/// lower (an older sample), not finite (a corrupted one) or missing changes nothing,
/// and one that grew faster than [`MAX_POWER_W`] since the last one believed is not
/// believed (one bogus value must not switch the passivity controller off for good).
#[derive(Debug, Clone, Copy, Default)]
struct Remote {
    energy: [f64; 3],
    samples_since: [u64; 3],
}

impl Remote {
    fn take(&mut self, received: [f64; 3], t_s: f64) {
        for (i, r) in received.into_iter().enumerate() {
            self.samples_since[i] += 1;
            let most = self.energy[i] + MAX_POWER_W * t_s * self.samples_since[i] as f64;
            if r.is_finite() && r > self.energy[i] && r <= most {
                self.energy[i] = r;
                self.samples_since[i] = 0;
            }
        }
    }
}

/// The force on the handle for one sample and what the control did.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct MasterForce {
    /// Force on the handle after control and the device's limit, N.
    pub force: [f64; 3],
    /// Components clamped to the force limit.
    pub clamped: u32,
    /// The master's passivity observer per axis after this sample, J.
    pub observer: [f64; 3],
    /// Energy the control dissipated this sample, J.
    pub dissipated: f64,
}

/// The master's side of the channel.
#[derive(Debug, Clone)]
pub struct MasterSide {
    cfg: ControlConfig,
    t_s: f64,
    ledger: Ledger,
    remote: Remote,
    velocity: [f64; 3],
    wave_in: [f64; 3],
    base: [f64; 3],
    applied: [f64; 3],
}

impl MasterSide {
    /// A master side at rest with sampling period `t_s`.
    pub fn new(cfg: &ControlConfig, t_s: f64) -> Self {
        MasterSide {
            cfg: cfg.clone(),
            t_s,
            ledger: Ledger::default(),
            remote: Remote::default(),
            velocity: [0.0; 3],
            wave_in: [0.0; 3],
            base: [0.0; 3],
            applied: [0.0; 3],
        }
    }

    /// The handle's displacement over the sample just ended, m (the master takes it
    /// from its encoders through the Jacobian, J (b(n) - b(n-1)): differencing the
    /// FK-HMD positions instead would turn the hybrid datapath's position error,
    /// tens of micrometres, into velocity noise of centimetres per second). Sets the
    /// velocity, and books the interval's energy, exactly for a force held over the
    /// sample: the force applied times the displacement.
    pub fn measure(&mut self, dx: [f64; 3]) {
        for (i, d) in dx.into_iter().enumerate() {
            self.velocity[i] = d / self.t_s;
            self.ledger.book(i, self.applied[i] * d);
        }
    }

    /// The handle's velocity estimate, m/s.
    pub fn velocity(&self) -> [f64; 3] {
        self.velocity
    }

    /// What is sent for position `c`: c itself, or the forward wave.
    pub fn transmit(&self, c: [f64; 3]) -> [f64; 3] {
        match self.cfg.kind {
            ControlKind::None | ControlKind::Tdpa | ControlKind::Mmt => c,
            ControlKind::Wave => {
                let s = (2.0 * self.cfg.wave_impedance).sqrt();
                [0, 1, 2].map(|i| s * self.velocity[i] + self.wave_in[i])
            }
        }
    }

    /// The energy this side has put into the channel, sent with every sample.
    pub fn energy(&self) -> [f64; 3] {
        self.ledger.input
    }

    /// This port's books.
    pub fn ledger(&self) -> &Ledger {
        &self.ledger
    }

    /// What came back (a force, or the backward wave) with the slave's input energy:
    /// the force on the handle, limited to `limit` per axis. A value that is not
    /// finite is never used (the caller rejects it and calls [`MasterSide::hold`]).
    pub fn receive(&mut self, value: [f64; 3], energy: [f64; 3], limit: f64) -> MasterForce {
        self.remote.take(energy, self.t_s);
        match self.cfg.kind {
            ControlKind::None | ControlKind::Tdpa | ControlKind::Mmt => self.base = value,
            ControlKind::Wave => {
                self.wave_in = value;
                self.base = self.wave_force();
            }
        }
        self.apply(limit)
    }

    /// No answer this sample: the last force acts again, or, with waves, the last wave
    /// held against the present velocity (the books still run).
    pub fn hold(&mut self, limit: f64) -> MasterForce {
        if self.cfg.kind == ControlKind::Wave {
            self.base = self.wave_force();
        }
        self.apply(limit)
    }

    /// The force on the handle from the wave last received: -(b v + sqrt(2b) w).
    fn wave_force(&self) -> [f64; 3] {
        let b = self.cfg.wave_impedance;
        let s = (2.0 * b).sqrt();
        [0, 1, 2].map(|i| -(b * self.velocity[i] + s * self.wave_in[i]))
    }

    /// The loop is broken: no force, and with waves the last wave forgotten, so what
    /// is sent forward asks the slave for the handle's motion alone and not for the
    /// force it had when the loop broke; the books still run.
    pub fn release(&mut self) -> MasterForce {
        self.base = [0.0; 3];
        self.wave_in = [0.0; 3];
        self.apply(0.0)
    }

    /// The force for the coming sample. Its energy is predicted with the present
    /// velocity (the passivity controller must act before the motion happens) and
    /// booked exactly at the next [`MasterSide::measure`]; the observer returned is the
    /// prediction after control.
    fn apply(&mut self, limit: f64) -> MasterForce {
        let mut out = MasterForce::default();
        for i in 0..3 {
            let v = self.velocity[i];
            let mut f = self.base[i];
            let w = self.remote.energy[i] - self.ledger.output[i] - (f * v * self.t_s).max(0.0);
            if self.cfg.kind == ControlKind::Tdpa && w < 0.0 && f * v > 0.0 {
                // Damping against the motion, at most enough to stop this sample's
                // output (a deficit left from earlier samples waits for the slave's
                // energy: pushing energy in here would not reduce it).
                let v2 = (v * v).max(self.cfg.velocity_floor.powi(2));
                let alpha = (-w / (self.t_s * v2)).min(self.cfg.max_damping).min(f / v);
                f -= alpha * v;
                out.dissipated += alpha * v * v * self.t_s;
            }
            let limited = f.clamp(-limit, limit);
            out.clamped += u32::from(limited != f);
            self.applied[i] = limited;
            out.force[i] = limited;
            out.observer[i] =
                self.remote.energy[i] - self.ledger.output[i] - (limited * v * self.t_s).max(0.0);
        }
        out
    }
}

/// The slave's reference for one sample and what the control did.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct SlaveReference {
    /// Cartesian position reference for the slave's controller, m.
    pub position: [f64; 3],
    /// The slave's passivity observer per axis after this sample, J.
    pub observer: [f64; 3],
    /// Energy the control dissipated this sample, J.
    pub dissipated: f64,
}

/// The slave's side of the channel.
#[derive(Debug, Clone)]
pub struct SlaveSide {
    cfg: ControlConfig,
    t_s: f64,
    ledger: Ledger,
    remote: Remote,
    last_received: Option<[f64; 3]>,
    reference: [f64; 3],
    wave_out: [f64; 3],
}

impl SlaveSide {
    /// A slave side whose reference starts at `start` (the tool's position at rest).
    pub fn new(cfg: &ControlConfig, t_s: f64, start: [f64; 3]) -> Self {
        SlaveSide {
            cfg: cfg.clone(),
            t_s,
            ledger: Ledger::default(),
            remote: Remote::default(),
            last_received: None,
            reference: start,
            wave_out: [0.0; 3],
        }
    }

    /// The energy this side has put into the channel, sent with every sample.
    pub fn energy(&self) -> [f64; 3] {
        self.ledger.input
    }

    /// This port's books.
    pub fn ledger(&self) -> &Ledger {
        &self.ledger
    }

    /// The current reference, m.
    pub fn position(&self) -> [f64; 3] {
        self.reference
    }

    /// A finite value arrived (a position, or the forward wave) with the master's input
    /// energy; `h` is the environment's force on the tool as last measured.
    pub fn receive(&mut self, value: [f64; 3], energy: [f64; 3], h: [f64; 3]) -> SlaveReference {
        self.remote.take(energy, self.t_s);
        let mut out = SlaveReference::default();
        for i in 0..3 {
            let fs = -h[i];
            let (v, extra) = match self.cfg.kind {
                ControlKind::None | ControlKind::Mmt if self.follows() => {
                    let v = self.velocity_to(i, value[i]);
                    (v, 0.0)
                }
                ControlKind::None | ControlKind::Mmt | ControlKind::Tdpa => {
                    self.passive_velocity(i, value[i], fs, &mut out)
                }
                ControlKind::Wave => {
                    let b = self.cfg.wave_impedance;
                    let v = ((2.0 * b).sqrt() * value[i] - fs) / (2.0 * b);
                    // The matching damper b in series: it takes b v^2.
                    let damper = b * v * v * self.t_s;
                    out.dissipated += damper;
                    // The returning wave pairs with the same force, so the port's
                    // power is exactly (u^2 - w^2) / 2.
                    self.wave_out[i] = fs / (2.0 * b).sqrt();
                    (v, damper)
                }
            };
            match self.cfg.kind {
                _ if self.follows() => self.reference[i] = value[i],
                _ => self.reference[i] += v * self.t_s,
            }
            self.ledger.book(i, fs * v * self.t_s + extra);
            out.observer[i] = self.remote.energy[i] - self.ledger.output[i];
        }
        self.last_received = Some(value);
        out.position = self.reference;
        out
    }

    /// What is sent back for the environment force `h`: h itself, or the backward
    /// wave of the force the last [`SlaveSide::receive`] resisted with.
    pub fn transmit(&self, h: [f64; 3]) -> [f64; 3] {
        match self.cfg.kind {
            ControlKind::None | ControlKind::Tdpa | ControlKind::Mmt => h,
            ControlKind::Wave => self.wave_out,
        }
    }

    /// The velocity that takes the reference from the last received position to `x`.
    /// The slave's reference is the received position itself: `none`, and MMT's
    /// slave unless `[control.mmt] slave = "tdpa"`.
    fn follows(&self) -> bool {
        match self.cfg.kind {
            ControlKind::None => true,
            ControlKind::Mmt => self.cfg.mmt.slave == MmtSlave::Follow,
            ControlKind::Tdpa | ControlKind::Wave => false,
        }
    }

    fn velocity_to(&self, i: usize, x: f64) -> f64 {
        self.last_received
            .map_or(0.0, |last| (x - last[i]) / self.t_s)
    }

    /// TDPA on axis i: the received motion, slowed where the observer would go negative,
    /// then the drift pulled back with whatever energy is left. Returns the velocity.
    fn passive_velocity(&self, i: usize, x: f64, fs: f64, out: &mut SlaveReference) -> (f64, f64) {
        let t = self.t_s;
        let mut v = self.velocity_to(i, x);
        let spare = (self.remote.energy[i] - self.ledger.output[i]).max(0.0);
        let out_j = fs * v * t;
        if out_j > spare {
            // Slow the motion so this sample takes out no more than there is: v scaled
            // towards 0, never past it (a deficit from earlier samples waits for the
            // master's energy, as at the master).
            let slowed = v * spare / out_j;
            out.dissipated += out_j - spare;
            v = slowed;
        }
        // Drift: the reference after this step against the master's position, pulled
        // back at up to drift_rate; a correction that takes energy out is paid from
        // what is left, one that puts energy in or moves in free space is free.
        let budget = spare - (fs * v * t).max(0.0);
        let drift = x - (self.reference[i] + v * t);
        if self.cfg.drift_rate > 0.0 {
            let mut vc = (drift / t).clamp(-self.cfg.drift_rate, self.cfg.drift_rate);
            let cost = fs * vc * t;
            if cost > budget.max(0.0) {
                vc *= budget.max(0.0) / cost;
            }
            v += vc;
        }
        (v, 0.0)
    }
}

#[cfg(test)]
mod tests;
