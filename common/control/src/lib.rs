//! What keeps a delayed bilateral channel stable and lean: the energy books and the
//! passivity observers, TDPA and wave variables ([`passivity`]), model-mediated
//! teleoperation's estimate and rendering ([`mmt`]), and the perceptual deadband codecs
//! with the receivers' predictors ([`codec`]). Pure per-sample state
//! machines that return commands; the nodes apply them. Settings are
//! `tactile-scenario`'s.

pub mod codec;
pub mod mmt;
pub mod passivity;
