//! The paper's hardware as RTL.
//!
//! - [`text`]: the hand-written Verilog (`common/rtl/hdl/`) and its generated parameters,
//!   from the model; `tactile hdl` writes them, co-simulates and synthesizes them.
//! - [`engine`]: the kernels' [`Engine`] for any arithmetic, `rtl` included: with the
//!   feature `verilator`, the modules FK, KFF, FBF and IK are compiled by Verilator
//!   into this crate (its build script) and every call runs them clock by clock.
//!   Without it, or with it but without Verilator when this crate was built (a
//!   machine with only Rust), `rtl` is refused with the reason.

pub mod text;

#[cfg(tactile_rtl_sim)]
mod sim;

#[cfg(tactile_rtl_sim)]
pub use sim::{Rtl, BUILT_FOR};

use tactile_math::arith::ArithKind;
use tactile_math::cordic::CordicConfig;
use tactile_math::engine::{Engine, EngineError};
use tactile_math::geometry::Geometry;

/// Why the RTL cannot serve a run.
#[derive(Debug, thiserror::Error)]
pub enum RtlError {
    /// The engine refused (format, or no hardware in this build).
    #[error(transparent)]
    Engine(#[from] EngineError),
    /// The RTL in this build was generated for another format or geometry.
    #[error("{0}")]
    Mismatch(String),
    /// Built with the feature `verilator`, but Verilator could not run when this crate
    /// was built, so the modules are not in it.
    #[error(
        "arithmetic \"rtl\" needs the RTL simulated by Verilator: this program was built \
         with the feature rtl but without Verilator on PATH (Debian: apt-get install \
         verilator make g++, then cargo clean -p tactile-rtl and rebuild)"
    )]
    NoVerilator,
}

impl RtlError {
    /// The scenario field the error is about: the format (`cordic`) or the choice of
    /// arithmetic.
    pub fn field(&self) -> &'static str {
        match self {
            RtlError::Engine(EngineError::Cordic(_)) => "cordic",
            _ => "arithmetic",
        }
    }
}

/// True when this build simulates the RTL (`arithmetic = "rtl"` works).
pub const AVAILABLE: bool = cfg!(tactile_rtl_sim);

/// The pipeline configuration this build simulates (`TACTILE_RTL_PIPELINE` when it
/// was built, by default [`text::Pipeline::Module`]): the clocks each call takes.
/// `None` in a build without the simulation.
pub fn built_pipeline() -> Option<text::Pipeline> {
    #[cfg(tactile_rtl_sim)]
    {
        sim::built_pipeline()
    }
    #[cfg(not(tactile_rtl_sim))]
    {
        None
    }
}

/// Whether this build can run `arithmetic = "rtl"` for `cordic` and `geometry`, without
/// making the simulator: what a launcher asks before it starts anything.
pub fn check(cordic: CordicConfig, geometry: Geometry) -> Result<(), RtlError> {
    #[cfg(tactile_rtl_sim)]
    {
        sim::check_built_for(&cordic, &geometry)
    }
    #[cfg(not(tactile_rtl_sim))]
    {
        let _ = (cordic, geometry);
        Err(missing())
    }
}

/// The engine for `kind`: software, or for [`ArithKind::Rtl`] the modules simulated
/// by Verilator (refused by a build without the feature, or built for another format
/// or geometry, with what to do).
pub fn engine(
    kind: ArithKind,
    geometry: Geometry,
    cordic: CordicConfig,
) -> Result<Engine, RtlError> {
    if kind != ArithKind::Rtl {
        return Ok(Engine::new(kind, geometry, cordic)?);
    }
    #[cfg(tactile_rtl_sim)]
    {
        let rtl = Rtl::new(&cordic, &geometry)?;
        Ok(Engine::with_hardware(geometry, cordic, Box::new(rtl))?)
    }
    #[cfg(not(tactile_rtl_sim))]
    {
        Err(missing())
    }
}

/// Why this build has no RTL: the feature is off, or Verilator was missing.
#[cfg(not(tactile_rtl_sim))]
fn missing() -> RtlError {
    if cfg!(feature = "verilator") {
        RtlError::NoVerilator
    } else {
        RtlError::Engine(EngineError::NoHardware)
    }
}
