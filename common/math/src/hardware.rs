//! The paper's modules in hardware: the RTL under simulation, clock by clock
//! (`arithmetic = "rtl"`, the crate `tactile-rtl` behind the feature `rtl`).
//!
//! The math crate only names what such hardware does, so [`crate::engine::Engine`] can
//! run its kernels through it without depending on a simulator: f32 in, f32 out, as
//! the modules' ports, and the clocks each sample spent in each module.

use crate::kernels::IkStatus;
use serde::{Deserialize, Serialize};

/// The four modules (FK-HMD and FK-HSD are one design), as hardware computes them.
pub trait Hardware: Send + std::fmt::Debug {
    /// FK: tool position of the joint angles.
    fn fk(&mut self, theta: [f32; 3]) -> [f32; 3];
    /// KFF: joint torques for `force`, and the Jacobian at `theta` (rows: position
    /// axes) as the module computes it on its way.
    fn kff(&mut self, theta: [f32; 3], force: [f32; 3]) -> ([f32; 3], [[f32; 3]; 3]);
    /// FBF: `h (obj - env)`.
    fn fbf(&mut self, obj: [f32; 3], env: [f32; 3], h: [f32; 3]) -> [f32; 3];
    /// IK: joint angles and whether the target was reachable.
    fn ik(&mut self, pos: [f32; 3]) -> ([f32; 3], IkStatus);
    /// What the modules have spent so far.
    fn clocks(&self) -> Clocks;
}

/// The clocks the hardware spent, per module in the order of [`Module::ALL`]: what a
/// run records (each node its own modules) and its report turns into time.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Serialize, Deserialize)]
pub struct Clocks {
    /// Samples put through each module.
    pub calls: [u64; 4],
    /// Clocks from each sample's input to its output, summed.
    pub total: [u64; 4],
    /// The fewest clocks one sample took (0: no call).
    pub min: [u32; 4],
    /// The most clocks one sample took.
    pub max: [u32; 4],
    /// Samples the hardware flagged as not computed (for the RTL: an angle beyond the
    /// TFB's range, or a pipeline that never answered); their outputs are NaN.
    pub faults: u64,
}

impl Clocks {
    /// Counts one sample through module `index` that took `clocks`.
    pub fn count(&mut self, index: usize, clocks: u32) {
        let first = self.calls[index] == 0;
        self.calls[index] += 1;
        self.total[index] += u64::from(clocks);
        self.min[index] = if first {
            clocks
        } else {
            self.min[index].min(clocks)
        };
        self.max[index] = self.max[index].max(clocks);
    }

    /// True when no sample went through any module (a software arithmetic).
    pub fn is_empty(&self) -> bool {
        self.calls.iter().all(|&c| c == 0)
    }

    /// These and `other`'s, added (a master's and a slave's into one chip's).
    pub fn merged(&self, other: &Clocks) -> Clocks {
        let mut m = *self;
        for i in 0..4 {
            m.calls[i] += other.calls[i];
            m.total[i] += other.total[i];
            m.min[i] = match (self.calls[i], other.calls[i]) {
                (0, _) => other.min[i],
                (_, 0) => self.min[i],
                _ => self.min[i].min(other.min[i]),
            };
            m.max[i] = self.max[i].max(other.max[i]);
        }
        m.faults += other.faults;
        m
    }
}

/// A module of the hardware, for counting its clocks.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Module {
    /// Forward kinematics (FK-HMD, FK-HSD).
    Fk,
    /// Kinesthetic feedback force (KFF-HMD); the Jacobian is its stage.
    Kff,
    /// Feedback force (FBF-HSD).
    Fbf,
    /// Inverse kinematics (IK-HSD).
    Ik,
}

impl Module {
    /// Every module, in the order [`Hardware::clocks`] counts them.
    pub const ALL: [Module; 4] = [Module::Fk, Module::Kff, Module::Fbf, Module::Ik];

    /// The name in reports.
    pub fn name(self) -> &'static str {
        match self {
            Module::Fk => "fk",
            Module::Kff => "kff",
            Module::Fbf => "fbf",
            Module::Ik => "ik",
        }
    }
}
