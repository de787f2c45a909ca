#!/usr/bin/env bash
# Builds incise and runs the default scene: the intestine pull, headless (the desktop
# preview and XR modes are not part of this build yet). Prints where the report is.
set -euo pipefail
cd "$(dirname "$0")/.."
source scripts/ensure-deps.sh
cargo build --release --locked
scene="${1:-config/intestine_pull.ron}"
out="out/$(basename "$scene" .ron)"
./target/release/incise run "$scene" --out "$out" --vtu-every 10
echo "open $out/run.pvd in ParaView to play the run"
