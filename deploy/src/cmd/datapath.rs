//! The datapath options `tactile kernels` and `tactile paper` share: arithmetic,
//! fixed-point format of the hybrid CORDIC block, and the device geometry.

use clap::{Args, ValueEnum};
use std::path::PathBuf;
use tactile_launch::error::Error;
use tactile_math::arith::ArithKind;
use tactile_math::cordic::{CordicConfig, Rounding};
use tactile_math::geometry::Geometry;

/// The kernel a `kernels` run evaluates.
#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum Module {
    /// Forward kinematics: theta1,theta2,theta3 -> x,y,z.
    Fk,
    /// Inverse kinematics: x,y,z -> theta1,theta2,theta3,reachable.
    Ik,
    /// Kinesthetic feedback force: theta1..3,fx,fy,fz -> tau1,tau2,tau3.
    Kff,
    /// Feedback force: x_obj..z_obj,x_env..z_env,hx,hy,hz -> fx,fy,fz.
    Fbf,
}

/// CLI spelling of [`ArithKind`].
#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum ArithArg {
    /// f64 reference.
    F64,
    /// f32 software model.
    F32,
    /// f32 with CORDIC in fixed point (the FPGA datapath).
    Hybrid,
}

impl From<ArithArg> for ArithKind {
    fn from(a: ArithArg) -> Self {
        match a {
            ArithArg::F64 => ArithKind::F64,
            ArithArg::F32 => ArithKind::F32,
            ArithArg::Hybrid => ArithKind::Hybrid,
        }
    }
}

/// CLI spelling of [`Rounding`].
#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum RoundingArg {
    /// Floor, what a plain arithmetic shift does.
    Truncate,
    /// Round half up.
    Nearest,
}

impl From<RoundingArg> for Rounding {
    fn from(r: RoundingArg) -> Self {
        match r {
            RoundingArg::Truncate => Rounding::Truncate,
            RoundingArg::Nearest => Rounding::Nearest,
        }
    }
}

/// Fixed-point format of the CORDIC block (the hybrid model's and the RTL's).
#[derive(Debug, Clone, Args)]
pub struct FormatArgs {
    /// Word length V of the signed fixed-point format [sV.N].
    #[arg(long, default_value_t = CordicConfig::S16_13.word)]
    pub word: u32,
    /// Fractional bits N of [sV.N].
    #[arg(long, default_value_t = CordicConfig::S16_13.frac)]
    pub frac: u32,
    /// CORDIC iterations (default derived from --frac).
    #[arg(long)]
    pub iterations: Option<u32>,
    /// Rounding in the float-to-fixed conversion and every shift.
    #[arg(long, value_enum, default_value_t = RoundingArg::Nearest)]
    pub rounding: RoundingArg,
}

/// Fixed-point format of the CORDIC block and the device geometry.
#[derive(Debug, Clone, Args)]
pub struct DatapathArgs {
    /// Fixed-point format.
    #[command(flatten)]
    pub format: FormatArgs,
    /// Device geometry: `paper`, `omni`, or a TOML file with l1, l2, l3, a (metres).
    #[arg(long, default_value = "paper")]
    pub device: String,
}

impl FormatArgs {
    /// The validated CORDIC configuration: the model's own check and error.
    pub fn cordic(&self) -> Result<CordicConfig, Error> {
        let rounding = Rounding::from(self.rounding);
        CordicConfig::new(self.word, self.frac, self.iterations, rounding)
            .map_err(|e| Error::BadInput(format!("bad fixed-point format: {e}")))
    }
}

impl DatapathArgs {
    /// The validated CORDIC configuration.
    pub fn cordic(&self) -> Result<CordicConfig, Error> {
        self.format.cordic()
    }

    /// The device geometry: a preset or a validated file.
    pub fn geometry(&self) -> Result<Geometry, Error> {
        if let Some(g) = Geometry::preset(&self.device) {
            return Ok(g);
        }
        let path = PathBuf::from(&self.device);
        let text = tactile_runtime::files::read_text(
            &path,
            "device file",
            tactile_runtime::files::MAX_DEVICE_BYTES,
        )
        .map_err(|e| {
            Error::BadInput(format!(
                "--device {}: not a preset (paper, omni); {e}",
                self.device
            ))
        })?;
        tactile_scenario::geometry_from_toml(&text)
            .map_err(|e| Error::BadInput(format!("{}: {e}", path.display())))
    }
}
