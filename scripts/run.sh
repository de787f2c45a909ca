#!/usr/bin/env bash
# Builds incise and runs the default scene: the intestine pull, headless (the desktop
# preview and XR modes are not part of this build yet). Prints where the report is.
set -euo pipefail
cd "$(dirname "$0")/.."
source scripts/ensure-deps.sh
# The portable release build, the one scripts/test.sh builds too, so the README's two
# commands compile the workspace once: the solver's SIMD lanes pick AVX2 at run time, as
# fast on the default scene as a -C target-cpu=native build (docs/performance.md,
# "Portable or built for the CPU"). INCISE_NATIVE=1: a build for this CPU in target/native.
if [ "${INCISE_NATIVE:-0}" = 1 ]; then
    target=target/native
    RUSTFLAGS="${RUSTFLAGS:-} -C target-cpu=native" cargo build --release --locked --target-dir "$target"
else
    target=target
    cargo build --release --locked
fi
scene="${1:-config/intestine_pull.ron}"
out="out/$(basename "$scene" .ron)"
"./$target/release/incise" run "$scene" --out "$out" --vtu-every 10
echo "open $out/run.pvd in ParaView to play the run"
