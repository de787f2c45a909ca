//! incise command-line entry point.
fn main() {}
