//! Shared set-up of the rheology tests: the shipped presets.
#![allow(dead_code)]

use std::path::Path;

use incise_sim::rheology::{RheologyMaterial, RheologyPresets};

/// The preset `name` from the shipped `config/rheology.ron`.
pub fn preset(name: &str) -> RheologyMaterial {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../config/rheology.ron");
    RheologyPresets::load(&path)
        .expect("config/rheology.ron loads")
        .get(name)
        .expect("preset exists")
}
