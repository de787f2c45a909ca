#!/usr/bin/env bash
# The whole test suite: unit, validation and end-to-end tests of every crate, in release
# mode (the physics validation steps tens of thousands of substeps). GPU tests run on any
# wgpu adapter (lavapipe without a GPU); with INCISE_REQUIRE_GPU=1 (CI) a missing adapter
# fails them instead of skipping. The XR tests run against Monado, built once by
# scripts/monado.sh; with INCISE_REQUIRE_XR=1 or CI set (CI) a Monado that cannot be built
# fails the run, elsewhere those tests skip.
set -euo pipefail
cd "$(dirname "$0")/.."
INCISE_TEST_DEPS=1 source scripts/ensure-deps.sh
if manifest="$(bash scripts/monado.sh)"; then
    export INCISE_MONADO_MANIFEST="$manifest"
elif [ -n "${CI:-}" ] || [ "${INCISE_REQUIRE_XR:-0}" = 1 ]; then
    echo "scripts/monado.sh failed: the XR tests need Monado here" >&2
    exit 1
else
    echo "Monado could not be built: the XR runtime tests will be skipped" >&2
fi
cargo test --workspace --release --locked "$@"
