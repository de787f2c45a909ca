#!/usr/bin/env bash
# The whole test suite: unit, validation and end-to-end tests of every crate, in release
# mode (the physics validation steps tens of thousands of substeps). GPU tests run on any
# wgpu adapter (lavapipe without a GPU); with INCISE_REQUIRE_GPU=1 (CI) a missing adapter
# fails them instead of skipping.
set -euo pipefail
cd "$(dirname "$0")/.."
INCISE_TEST_DEPS=1 source scripts/ensure-deps.sh
cargo test --workspace --release --locked "$@"
