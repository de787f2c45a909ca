#!/usr/bin/env bash
# The whole test suite: unit, validation and end-to-end tests of every crate, in release
# mode (the physics validation steps tens of thousands of substeps).
set -euo pipefail
cd "$(dirname "$0")/.."
source scripts/ensure-deps.sh
cargo test --workspace --release --locked "$@"
