//! Runtime choice of arithmetic for the kernels.
//!
//! Processes and the command line pick the arithmetic at run time; [`Engine`] holds the
//! geometry in each precision and the CORDIC tables, and dispatches every call to the
//! monomorphised kernel. Values cross the interface as f64: an f32 or hybrid kernel
//! rounds its inputs to f32 (exactly what an f32 datapath receives) and its f32 outputs
//! widen to f64 exactly, so nothing is lost in either direction.

use crate::arith::{ArithKind, StdTrig};
use crate::cordic::{Cordic, CordicConfig, CordicError};
use crate::geometry::{Geometry, Lengths};
use crate::hardware::{Clocks, Hardware};
use crate::kernels::{self, IkStatus};
use std::sync::{Arc, Mutex, MutexGuard};

/// Kernels bound to one geometry and one arithmetic.
#[derive(Debug, Clone)]
pub struct Engine {
    kind: ArithKind,
    geometry: Geometry,
    g64: Lengths<f64>,
    g32: Lengths<f32>,
    cordic: Cordic,
    /// The RTL under simulation, for [`ArithKind::Rtl`] (shared by clones: one chip).
    hardware: Option<Arc<Mutex<Box<dyn Hardware>>>>,
}

/// Why an engine cannot be made.
#[derive(Debug, PartialEq, Eq, thiserror::Error)]
pub enum EngineError {
    /// The fixed-point format is not one the model takes.
    #[error(transparent)]
    Cordic(#[from] CordicError),
    /// `rtl` runs on hardware, which [`Engine::new`] cannot make.
    #[error(
        "arithmetic \"rtl\" needs the RTL simulated by Verilator: this program was built \
         without it (build with --features rtl)"
    )]
    NoHardware,
}

/// Result of [`Engine::ik`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct IkOut {
    /// Joint angles, radians, always finite.
    pub theta: [f64; 3],
    /// Reachable, clamped or invalid.
    pub status: IkStatus,
}

fn to32(v: [f64; 3]) -> [f32; 3] {
    v.map(|x| x as f32)
}

fn to64(v: [f32; 3]) -> [f64; 3] {
    v.map(f64::from)
}

impl Engine {
    /// An engine for `kind`; `cordic` matters only for [`ArithKind::Hybrid`]. `Rtl`
    /// needs its hardware: [`Engine::with_hardware`].
    pub fn new(
        kind: ArithKind,
        geometry: Geometry,
        cordic: CordicConfig,
    ) -> Result<Self, EngineError> {
        if kind == ArithKind::Rtl {
            return Err(EngineError::NoHardware);
        }
        Ok(Engine {
            kind,
            geometry,
            g64: geometry.lengths(),
            g32: geometry.lengths(),
            cordic: Cordic::new(cordic)?,
            hardware: None,
        })
    }

    /// An [`ArithKind::Rtl`] engine: every kernel computed by `hardware`, which must
    /// have been built for this geometry and format (the caller's contract).
    pub fn with_hardware(
        geometry: Geometry,
        cordic: CordicConfig,
        hardware: Box<dyn Hardware>,
    ) -> Result<Self, EngineError> {
        Ok(Engine {
            kind: ArithKind::Rtl,
            geometry,
            g64: geometry.lengths(),
            g32: geometry.lengths(),
            cordic: Cordic::new(cordic)?,
            hardware: Some(Arc::new(Mutex::new(hardware))),
        })
    }

    /// The hardware, for [`ArithKind::Rtl`]. A panic while it was held leaves it
    /// usable: every call sets all its inputs.
    fn hw(&self) -> MutexGuard<'_, Box<dyn Hardware>> {
        let hw = self
            .hardware
            .as_ref()
            .expect("an rtl engine is made with its hardware");
        hw.lock().unwrap_or_else(|poisoned| poisoned.into_inner())
    }

    /// The clocks the hardware has spent in each module; zero for software.
    pub fn hardware_clocks(&self) -> Clocks {
        self.hardware
            .as_ref()
            .map_or_else(Clocks::default, |_| self.hw().clocks())
    }

    /// The arithmetic in use.
    pub fn kind(&self) -> ArithKind {
        self.kind
    }

    /// The device geometry in use.
    pub fn geometry(&self) -> &Geometry {
        &self.geometry
    }

    /// The CORDIC model (used by hybrid).
    pub fn cordic(&self) -> &Cordic {
        &self.cordic
    }

    /// Forward kinematics.
    pub fn fk(&self, theta: [f64; 3]) -> [f64; 3] {
        match self.kind {
            ArithKind::F64 => kernels::fk(&self.g64, &StdTrig, theta),
            ArithKind::F32 => to64(kernels::fk(&self.g32, &StdTrig, to32(theta))),
            ArithKind::Hybrid => to64(kernels::fk(&self.g32, &self.cordic, to32(theta))),
            ArithKind::Rtl => to64(self.hw().fk(to32(theta))),
        }
    }

    /// Inverse kinematics, flagged and clamped outside the workspace.
    pub fn ik(&self, pos: [f64; 3]) -> IkOut {
        match self.kind {
            ArithKind::F64 => {
                let s = kernels::ik(&self.g64, &StdTrig, pos);
                IkOut {
                    theta: s.theta,
                    status: s.status,
                }
            }
            ArithKind::F32 => {
                let s = kernels::ik(&self.g32, &StdTrig, to32(pos));
                IkOut {
                    theta: to64(s.theta),
                    status: s.status,
                }
            }
            ArithKind::Hybrid => {
                let s = kernels::ik(&self.g32, &self.cordic, to32(pos));
                IkOut {
                    theta: to64(s.theta),
                    status: s.status,
                }
            }
            ArithKind::Rtl => {
                let (theta, status) = self.hw().ik(to32(pos));
                IkOut {
                    theta: to64(theta),
                    status,
                }
            }
        }
    }

    /// Jacobian of forward kinematics.
    pub fn jacobian(&self, theta: [f64; 3]) -> [[f64; 3]; 3] {
        let widen = |j: [[f32; 3]; 3]| j.map(to64);
        match self.kind {
            ArithKind::F64 => kernels::jacobian(&self.g64, &StdTrig, theta),
            ArithKind::F32 => widen(kernels::jacobian(&self.g32, &StdTrig, to32(theta))),
            ArithKind::Hybrid => widen(kernels::jacobian(&self.g32, &self.cordic, to32(theta))),
            // KFF computes J on its way to the torques: the module's own stage.
            ArithKind::Rtl => widen(self.hw().kff(to32(theta), [0.0; 3]).1),
        }
    }

    /// Joint torques `J^T F`.
    pub fn kff(&self, theta: [f64; 3], force: [f64; 3]) -> [f64; 3] {
        match self.kind {
            ArithKind::F64 => kernels::kff(&self.g64, &StdTrig, theta, force),
            ArithKind::F32 => to64(kernels::kff(&self.g32, &StdTrig, to32(theta), to32(force))),
            ArithKind::Hybrid => to64(kernels::kff(
                &self.g32,
                &self.cordic,
                to32(theta),
                to32(force),
            )),
            ArithKind::Rtl => to64(self.hw().kff(to32(theta), to32(force)).0),
        }
    }

    /// Contact force `h * (obj - env)`.
    pub fn fbf(&self, obj: [f64; 3], env: [f64; 3], h: [f64; 3]) -> [f64; 3] {
        match self.kind {
            ArithKind::F64 => kernels::fbf(obj, env, h),
            ArithKind::F32 | ArithKind::Hybrid => to64(kernels::fbf(to32(obj), to32(env), to32(h))),
            ArithKind::Rtl => to64(self.hw().fbf(to32(obj), to32(env), to32(h))),
        }
    }
}
