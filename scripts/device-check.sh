#!/usr/bin/env bash
# One short check for a machine with a real GPU (issue 17): the GPU tests, the realtime
# benchmark of the default organ (34k tets) on XPBD on the GPU (a dispatch per colour, and
# the partitioned order's dispatch per phase), the default scene (that organ on the
# implicit scheme, issue 31: its ms and dispatches a frame) on the GPU and the CPU, that
# scene in a simulated Quest 3 whose eyes the GPU draws at full size (the solver on the
# CPU on its own thread: the latency a trainee would feel), the solver benchmark
# up to ≥ 1M tets on the GPU, and a CPU/GPU parity run, written as one JSON object to
# ${OUT:-.}/device-check.json (stdout and stderr of each step beside it). Under 5 minutes
# on a datacentre GPU once built; the build itself is not timed.
#
#   bash scripts/device-check.sh            # writes ./device-check.json
#   OUT=/tmp/x bash scripts/device-check.sh
set -uo pipefail
cd "$(dirname "$0")/.."
out="${OUT:-.}"
mkdir -p "$out"
export INCISE_REQUIRE_GPU=1
export XDG_RUNTIME_DIR="${XDG_RUNTIME_DIR:-$(mktemp -d)}"
export PATH="$HOME/.cargo/bin:$PATH"
cargo build --release --locked --workspace --all-targets >"$out/build.log" 2>&1 || {
    echo '{"error": "build failed, see build.log"}' >"$out/device-check.json"
    exit 1
}
bin=target/release/incise

# step NAME COMMAND...: run it with a 150 s limit, keep its output, record its exit code.
step() {
    local name="$1"
    shift
    local t0=$SECONDS
    timeout 150 "$@" >"$out/$name.out" 2>"$out/$name.err"
    local rc=$?
    echo "\"$name\": {\"rc\": $rc, \"seconds\": $((SECONDS - t0))}" >"$out/$name.rc"
}

step gpu_tests cargo test --release --locked -p incise-sim --test gpu_parity --test gpu_validation --test gpu_newton
step realtime_gpu "$bin" bench realtime --scene config/intestine_pull_xpbd.ron --device gpu --frames 60 --json
step realtime_gpu_blocks "$bin" bench realtime --scene config/intestine_pull_xpbd.ron --device gpu --cpu-sweep blocks --frames 60 --json
step realtime_gpu_newton "$bin" bench realtime --device gpu --frames 60 --json
step realtime_cpu "$bin" bench realtime --device cpu --frames 10 --json
step scaling_gpu "$bin" bench solver --device gpu --case intestine --scaling --frames 5 --json
step parity "$bin" compare config/intestine_pull.ron --json
cat >"$out/headset.ron" <<'SCRIPT'
(display_hz: 72.0, duration: 2.0, render_every: 1, realtime: true,
 head: [(t: 0.0, position: (0.0, 1.25, -0.05), orientation: (-0.34202, 0.0, 0.0, 0.93969))])
SCRIPT
step headset_gpu "$bin" xr config/intestine_pull.ron --simulated-headset "$out/headset.ron" \
    --device cpu --out "$out/headset"

{
    echo "{"
    echo "\"machine\": \"$(uname -n) $(nvidia-smi --query-gpu=name --format=csv,noheader 2>/dev/null | head -1)\","
    echo "\"date\": \"$(date -u +%FT%TZ)\", \"load\": \"$(cut -d' ' -f1-3 /proc/loadavg)\","
    echo "\"steps\": {"
    cat "$out"/gpu_tests.rc; echo ","
    cat "$out"/realtime_gpu.rc; echo ","
    cat "$out"/realtime_gpu_blocks.rc; echo ","
    cat "$out"/realtime_gpu_newton.rc; echo ","
    cat "$out"/realtime_cpu.rc; echo ","
    cat "$out"/scaling_gpu.rc; echo ","
    cat "$out"/parity.rc; echo ","
    cat "$out"/headset_gpu.rc
    echo "},"
    echo "\"headset_gpu\": $(cat "$out/headset/xr_report.json" 2>/dev/null || echo null),"
    for s in realtime_gpu realtime_gpu_blocks realtime_gpu_newton realtime_cpu scaling_gpu parity; do
        echo "\"$s\": $(if [ -s "$out/$s.out" ] && head -c1 "$out/$s.out" | grep -q '[{[]'; then cat "$out/$s.out"; else echo null; fi),"
    done
    echo "\"gpu_tests_summary\": \"$(grep -E '^test result' "$out/gpu_tests.out" | tr '\n' ' ')\""
    echo "}"
} >"$out/device-check.json"
cat "$out/device-check.json"
