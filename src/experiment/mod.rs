//! Reproducible experiments that regenerate the figures and tables in `docs/experiments/`.

pub mod doc_table;
pub mod nakao;
pub mod nakao_bench;
pub mod nakao_chest;
pub mod nakao_counts;
pub mod rheology;
pub mod scene_figures;
pub mod substep_budget;
