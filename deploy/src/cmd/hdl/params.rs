//! The RTL in a folder: its sources and generated parameters (`tactile_rtl::text`),
//! each block's latency in each pipeline configuration, and the model a format's RTL
//! is checked against.

use std::path::Path;
use tactile_launch::error::Error;
use tactile_math::cordic::hdl::{RtlConstants, REDUCE_GUARD};
use tactile_math::cordic::{Cordic, CordicConfig};
use tactile_math::geometry::Geometry;
use tactile_rtl::text::{files, Block, Pipeline};

/// Clocks from input to output of each block in a pipeline configuration
/// ([`Pipeline::latency`]).
pub fn latency(block: Block, cfg: &CordicConfig, p: Pipeline) -> u32 {
    p.latency(block, cfg.iterations)
}

/// The model for `cfg`, refused (with the model's error) where the model refuses it,
/// and where the RTL's integer range reduction would not give the model's codes.
pub fn model(cfg: CordicConfig) -> Result<(Cordic, RtlConstants), Error> {
    let cordic =
        Cordic::new(cfg).map_err(|e| Error::BadInput(format!("bad fixed-point format: {e}")))?;
    let constants = cordic.rtl_constants();
    if let Some(a) = cordic.rtl_reduction_mismatch(&constants) {
        return Err(Error::BadInput(format!(
            "no RTL for this format: its range reduction in {REDUCE_GUARD} guard bits \
             differs from the model's at angle {a:e}"
        )));
    }
    Ok((cordic, constants))
}

/// Writes the sources, `tfb_params.vh`, `kin_params.vh` (the modules' constants
/// for `geometry`) and `pipe.vh` into `dir` (created if missing).
pub fn write_rtl(
    dir: &Path,
    c: &RtlConstants,
    geometry: &Geometry,
    pipeline: Pipeline,
) -> Result<(), Error> {
    std::fs::create_dir_all(dir).map_err(Error::io(format!("creating {}", dir.display())))?;
    for (name, text) in files(c, geometry, pipeline) {
        let path = dir.join(name);
        std::fs::write(&path, text).map_err(Error::io(format!("writing {}", path.display())))?;
    }
    Ok(())
}
