//! The modules simulated by Verilator (built by this crate's build script), behind the
//! kernels' [`Hardware`] trait: each call clocks one sample through a module's
//! pipeline and counts the clocks it took.

// The one place the workspace calls C++: four functions over plain u32 arrays, their
// lengths fixed by glue.cpp, and a pointer owned by `Rtl` alone.
#![allow(unsafe_code)]

use crate::text::{kin_params_vh, params_vh, pipe_vh, Pipeline};
use crate::RtlError;
use std::ffi::c_void;
use std::ptr::NonNull;
use tactile_math::cordic::{Cordic, CordicConfig};
use tactile_math::geometry::Geometry;
use tactile_math::hardware::{Clocks, Hardware};
use tactile_math::kernels::IkStatus;

extern "C" {
    fn tactile_rtl_new() -> *mut c_void;
    fn tactile_rtl_free(chip: *mut c_void);
    fn tactile_rtl_fk(chip: *mut c_void, input: *const u32, output: *mut u32) -> u32;
    fn tactile_rtl_kff(chip: *mut c_void, input: *const u32, output: *mut u32) -> u32;
    fn tactile_rtl_fbf(chip: *mut c_void, input: *const u32, output: *mut u32) -> u32;
    fn tactile_rtl_ik(chip: *mut c_void, input: *const u32, output: *mut u32) -> u32;
}

/// The parameter files the simulated RTL was built with (`tfb_params.vh`,
/// `kin_params.vh`): the format and geometry a run must ask for.
pub const BUILT_FOR: (&str, &str) = (
    include_str!(concat!(env!("OUT_DIR"), "/rtl/tfb_params.vh")),
    include_str!(concat!(env!("OUT_DIR"), "/rtl/kin_params.vh")),
);

/// The pipeline configuration the simulated RTL was built with: the one whose
/// `pipe.vh` the build wrote (the build script and this crate generate it from the
/// same text, so exactly one matches).
pub(crate) fn built_pipeline() -> Option<Pipeline> {
    let built = include_str!(concat!(env!("OUT_DIR"), "/rtl/pipe.vh"));
    Pipeline::ALL.into_iter().find(|p| pipe_vh(*p) == built)
}

/// The four modules under simulation: one chip, one sample in flight at a time.
#[derive(Debug)]
pub struct Rtl {
    chip: NonNull<c_void>,
    clocks: Clocks,
}

// The chip is plain memory owned by this value alone and only touched through
// `&mut self`, so it may move to another thread.
unsafe impl Send for Rtl {}

fn bits<const N: usize>(v: [f32; N]) -> [u32; N] {
    v.map(f32::to_bits)
}

fn floats<const N: usize>(v: [u32; N]) -> [f32; N] {
    v.map(f32::from_bits)
}

/// Whether the simulated RTL was built for `cordic` and `geometry`: the parameter files
/// are generated again and must equal the built ones.
pub(crate) fn check_built_for(cordic: &CordicConfig, geometry: &Geometry) -> Result<(), RtlError> {
    let model = Cordic::new(*cordic).map_err(tactile_math::engine::EngineError::from)?;
    if params_vh(&model.rtl_constants()) != BUILT_FOR.0 {
        return Err(RtlError::Mismatch(format!(
            "the RTL in this build is for another fixed-point format than [s{}.{}] {:?} \
             (rebuild with TACTILE_RTL_WORD, TACTILE_RTL_FRAC and TACTILE_RTL_ROUNDING set)",
            cordic.word, cordic.frac, cordic.rounding
        )));
    }
    if kin_params_vh(geometry) != BUILT_FOR.1 {
        return Err(RtlError::Mismatch(
            "the RTL in this build is for another device geometry \
             (rebuild with TACTILE_RTL_DEVICE=paper or omni)"
                .into(),
        ));
    }
    Ok(())
}

impl Rtl {
    /// The chip, if it was built for `cordic` and `geometry` ([`check_built_for`]).
    pub fn new(cordic: &CordicConfig, geometry: &Geometry) -> Result<Rtl, RtlError> {
        check_built_for(cordic, geometry)?;
        // SAFETY: tactile_rtl_new allocates and returns a chip, never null (new throws).
        let chip = NonNull::new(unsafe { tactile_rtl_new() })
            .ok_or_else(|| RtlError::Mismatch("the simulator could not be created".into()))?;
        Ok(Rtl {
            chip,
            clocks: Clocks::default(),
        })
    }

    /// Clocks one sample through module `index` with `f`; counts it.
    fn run<const I: usize, const O: usize>(
        &mut self,
        index: usize,
        f: unsafe extern "C" fn(*mut c_void, *const u32, *mut u32) -> u32,
        input: [u32; I],
    ) -> [u32; O] {
        let mut out = [0u32; O];
        // SAFETY: glue.cpp reads exactly I words and writes exactly O words for each
        // function (the callers pass the sizes written there); the chip is live.
        let clocks = unsafe { f(self.chip.as_ptr(), input.as_ptr(), out.as_mut_ptr()) };
        if clocks == 0 {
            self.clocks.faults += 1;
            out = [f32::NAN.to_bits(); O];
        }
        self.clocks.count(index, clocks);
        out
    }
}

impl Drop for Rtl {
    fn drop(&mut self) {
        // SAFETY: the chip came from tactile_rtl_new and is freed once, here.
        unsafe { tactile_rtl_free(self.chip.as_ptr()) }
    }
}

impl Hardware for Rtl {
    fn fk(&mut self, theta: [f32; 3]) -> [f32; 3] {
        let o: [u32; 4] = self.run(0, tactile_rtl_fk, bits(theta));
        self.clocks.faults += u64::from(o[3] & 1);
        floats([o[0], o[1], o[2]])
    }

    fn kff(&mut self, theta: [f32; 3], force: [f32; 3]) -> ([f32; 3], [[f32; 3]; 3]) {
        let [t1, t2, t3] = bits(theta);
        let [f1, f2, f3] = bits(force);
        let o: [u32; 13] = self.run(1, tactile_rtl_kff, [t1, t2, t3, f1, f2, f3]);
        self.clocks.faults += u64::from(o[3] & 1);
        let j = |r: usize| floats([o[4 + 3 * r], o[5 + 3 * r], o[6 + 3 * r]]);
        (floats([o[0], o[1], o[2]]), [j(0), j(1), j(2)])
    }

    fn fbf(&mut self, obj: [f32; 3], env: [f32; 3], h: [f32; 3]) -> [f32; 3] {
        let (o, e, h) = (bits(obj), bits(env), bits(h));
        let input = [o[0], o[1], o[2], e[0], e[1], e[2], h[0], h[1], h[2]];
        floats(self.run::<9, 3>(2, tactile_rtl_fbf, input))
    }

    fn ik(&mut self, pos: [f32; 3]) -> ([f32; 3], IkStatus) {
        let o: [u32; 4] = self.run(3, tactile_rtl_ik, bits(pos));
        let status = match o[3] {
            0 => IkStatus::Reachable,
            1 => IkStatus::Clamped,
            _ => IkStatus::Invalid,
        };
        (floats([o[0], o[1], o[2]]), status)
    }

    fn clocks(&self) -> Clocks {
        self.clocks
    }
}
