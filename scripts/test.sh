#!/usr/bin/env bash
# The whole test suite: unit, validation and end-to-end tests of every crate, in release
# mode (the physics validation steps tens of thousands of substeps). GPU tests run on any
# wgpu adapter (lavapipe without a GPU), the XR tests against Monado (built once by
# scripts/monado.sh), the report test in chromium. Whether a missing one fails or skips
# is one rule (crates/test-gate): INCISE_REQUIRE_GPU, INCISE_REQUIRE_XR and
# INCISE_REQUIRE_BROWSER take 1 (fail), 0 (skip) or unset (skip, but fail when CI is set);
# any other value is an error.
#
# `scripts/test.sh --slow [CARGO TEST TARGETS]` is CI's second step instead (.ci/run runs it
# after the whole suite): every test marked #[ignore], in every crate, because it takes a
# minute or so (the full experiments against docs/experiments/, the large-scene docs
# figures), about 3 minutes in all on 2 cores once the suite has built them. It needs no
# GPU, browser or XR runtime, so it builds no Monado.
#
# `scripts/test-under-load.sh [ARGS]` runs this script (ARGS passed through) with one busy
# loop per core beside it: the suite must pass with both cores of a 2-core machine busy
# (tests of pacing and rates use a clock they own or ratios within one run).
set -euo pipefail
cd "$(dirname "$0")/.."

# required VAR: whether a missing need fails (exit 0) or skips (exit 1), by crates/test-gate's
# rule; an unknown value stops the run.
required() {
    local var="$1" value="${!1:-}"
    case "$value" in
        1) return 0 ;;
        0) return 1 ;;
        "") [ -n "${CI:-}" ] ;;
        *)
            echo "$var=$value is not understood: use 1 (fail), 0 (skip) or leave it unset (skip, but fail when CI is set)" >&2
            exit 2
            ;;
    esac
}
# Every gate's value is checked before anything is built.
for var in INCISE_REQUIRE_GPU INCISE_REQUIRE_XR INCISE_REQUIRE_BROWSER; do
    required "$var" || true
done

if [ "${1:-}" = "--slow" ]; then
    shift
    source scripts/ensure-deps.sh
    # All test harnesses (--tests: not the doctests, which the suite has run), or the
    # targets named (`--slow --test experiments_cli`).
    [ $# -gt 0 ] || set -- --tests
    exec cargo test --workspace --release --locked "$@" -- --ignored
fi

INCISE_TEST_DEPS=1 source scripts/ensure-deps.sh
if manifest="$(bash scripts/monado.sh)"; then
    export INCISE_MONADO_MANIFEST="$manifest"
elif required INCISE_REQUIRE_XR; then
    echo "scripts/monado.sh failed: the XR tests need Monado here" >&2
    exit 1
else
    echo "Monado could not be built: the XR runtime tests will be skipped" >&2
fi
cargo test --workspace --release --locked "$@"
