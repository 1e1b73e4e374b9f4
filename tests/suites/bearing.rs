//! The air bearing: the flow factor, the Reynolds solver, the slider's geometry and attitude, the
//! pitching slider, and the slider's Jacobian.
//!
//! One test program of several (Cargo.toml, `[[test]]`): each file below stays a file of its own
//! under `tests/`, and its tests are named `<file>::<test>`.

#[path = "../bearing_flow_factor.rs"]
mod bearing_flow_factor;
#[path = "../bearing_geometry.rs"]
mod bearing_geometry;
#[path = "../bearing_limits.rs"]
mod bearing_limits;
#[path = "../bearing_pitch_scene.rs"]
mod bearing_pitch_scene;
#[path = "../bearing_pitch_structure.rs"]
mod bearing_pitch_structure;
#[path = "../bearing_scene.rs"]
mod bearing_scene;
#[path = "../bearing_slider.rs"]
mod bearing_slider;
#[path = "../slider_jacobian.rs"]
mod slider_jacobian;
