//! The RTL's range reduction (integers, `cordic::hdl`) gives the model's angle code
//! for every f32 it reduces, in each format the co-simulation runs.

use tactile_math::cordic::{Cordic, CordicConfig, Rounding};

#[test]
fn the_rtl_reduction_is_the_models_for_every_reduced_angle() {
    for (word, frac) in [(16, 13), (24, 21), (32, 29)] {
        for rounding in [Rounding::Nearest, Rounding::Truncate] {
            let cfg = CordicConfig::new(word, frac, None, rounding).expect("a valid format");
            let c = Cordic::new(cfg).expect("a valid format");
            let k = c.rtl_constants();
            assert_eq!(
                c.rtl_reduction_mismatch(&k),
                None,
                "[s{word}.{frac}] {rounding:?}"
            );
        }
    }
}
