//! The incise application: scenes, the simulated bodies of the three methods, the
//! headless runner, reports, pictures, benchmarks and mesh tools. The binary in `main.rs`
//! is a thin CLI over these modules; `tests/` drives both.

pub mod bench;
pub mod cli;
pub mod compare;
pub mod doctor;
pub mod exercise;
pub mod experiment;
pub mod interrupt;
pub mod mesh_cmd;
pub mod pictures;
pub mod preview;
pub mod progress;
pub mod provenance;
mod quantile;
pub mod report;
pub mod run;
pub mod scene;
pub mod sim_body;
pub mod xr;
