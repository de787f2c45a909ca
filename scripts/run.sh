#!/usr/bin/env bash
# Builds incise and runs the default scene: the intestine pull, headless (the desktop
# preview and XR modes are not part of this build yet). Prints where the report is.
set -euo pipefail
cd "$(dirname "$0")/.."
source scripts/ensure-deps.sh
# Built for this machine's CPU (AVX2/AVX-512 SIMD lanes for the tet projection: the default
# scene's frame is 1.6x faster than the portable build, docs/performance.md), in its own
# target folder so the portable build of the tests is not rebuilt. INCISE_PORTABLE=1: the
# portable build.
if [ "${INCISE_PORTABLE:-0}" = 1 ]; then
    target=target
    cargo build --release --locked
else
    target=target/native
    RUSTFLAGS="${RUSTFLAGS:-} -C target-cpu=native" cargo build --release --locked --target-dir "$target"
fi
scene="${1:-config/intestine_pull.ron}"
out="out/$(basename "$scene" .ron)"
"./$target/release/incise" run "$scene" --out "$out" --vtu-every 10
echo "open $out/run.pvd in ParaView to play the run"
