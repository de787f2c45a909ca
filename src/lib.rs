//! The incise application: scenes, the headless runner, reports, benchmarks and mesh tools.
//! The binary in `main.rs` is a thin CLI over these modules; `tests/` drives both.

pub mod bench;
pub mod bench_realtime;
pub mod bench_render;
pub mod body;
pub mod cli;
pub mod compare;
pub mod exercise;
pub mod experiment;
pub mod interrupt;
pub mod loop_report;
mod mass_spring_frames;
pub mod mesh_cmd;
pub mod plot;
pub mod preview;
pub mod progress;
pub mod provenance;
pub mod report;
pub mod run;
pub mod run_mass_spring;
pub mod run_rheology;
pub mod scene;
pub mod screenshots;
pub mod soak;
pub mod tool_view;
pub mod xr;
