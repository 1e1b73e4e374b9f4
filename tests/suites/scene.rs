//! Scenes: files, units and errors, the structure presets, bad input to every constructor and the
//! scene reader, property tests of serialisation, and the extreme scenes.
//!
//! One test program of several (Cargo.toml, `[[test]]`): each file below stays a file of its own
//! under `tests/`, and its tests are named `<file>::<test>`.

// Several files include the same helper file (`tests/common/`, `examples/common/`) as a module
// of their own, as they did when each file was a program.
#![allow(clippy::duplicate_mod)]

#[path = "../bad_input_constructors.rs"]
mod bad_input_constructors;
#[path = "../bad_input_fuzz.rs"]
mod bad_input_fuzz;
#[path = "../extreme_scenes.rs"]
mod extreme_scenes;
#[path = "../extreme_smooth_limit.rs"]
mod extreme_smooth_limit;
#[path = "../extreme_stiffness.rs"]
mod extreme_stiffness;
#[path = "../invariants_scene.rs"]
mod invariants_scene;
#[path = "../regressions_fuzz.rs"]
mod regressions_fuzz;
#[path = "../regressions_scene.rs"]
mod regressions_scene;
#[path = "../scene_engineering_units.rs"]
mod scene_engineering_units;
#[path = "../scene_errors.rs"]
mod scene_errors;
#[path = "../scene_files.rs"]
mod scene_files;
#[path = "../structure_presets.rs"]
mod structure_presets;
