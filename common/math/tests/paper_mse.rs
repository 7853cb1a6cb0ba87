//! The paper's MSE table reproduced: hybrid against f32 on the validation run.

use tactile_math::cordic::{CordicConfig, Rounding};
use tactile_math::geometry::Geometry;
use tactile_math::validation::mse_table;

#[test]
fn s16_13_is_no_worse_than_the_paper_for_every_row() {
    let rows = mse_table(&Geometry::PAPER, CordicConfig::S16_13).expect("valid format");
    assert_eq!(rows.len(), 15);
    for r in &rows {
        assert!(
            r.mse <= r.paper_mse,
            "{} {}: ours {:e} > paper {:e}",
            r.module,
            r.variable,
            r.mse,
            r.paper_mse
        );
    }
    // The table measures something: the trig modules do differ from f32.
    assert!(rows
        .iter()
        .filter(|r| r.module != "FBF-HSD")
        .all(|r| r.mse > 0.0));
}

#[test]
fn s32_29_is_far_better_than_s16_13() {
    let wide = CordicConfig::new(32, 29, None, Rounding::Nearest).expect("valid format");
    let narrow = mse_table(&Geometry::PAPER, CordicConfig::S16_13).expect("valid");
    let rows = mse_table(&Geometry::PAPER, wide).expect("valid");
    for (w, n) in rows.iter().zip(&narrow) {
        assert!(
            w.mse <= n.mse * 1e-4 && w.mse <= w.paper_mse * 1e-4,
            "{} {}: [s32.29] {:e} vs [s16.13] {:e}",
            w.module,
            w.variable,
            w.mse,
            n.mse
        );
    }
}
