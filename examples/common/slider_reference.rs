//! The tolerances of the slider's reference cycles, shared by the work–precision example and the
//! reference-accuracy bench so that both measure against the same reference.
#![allow(dead_code)]

/// Relative tolerance of the slider reference (Tsit5; Radau5 at the same rtol checks it).
pub const SLIDER_REF_RTOL: f64 = 1e-11;

/// Absolute tolerance on the displacement per unit relative tolerance (m): the scene's
/// 1e-14 m at rtol 1e-6, i.e. rtol × 10 nm, the size of the spacing.
pub const SLIDER_ATOL_PER_RTOL: f64 = 1e-8;
