#!/usr/bin/env bash
# The whole suite (scripts/test.sh, its arguments passed through: `--test xr_cli`, `--slow`)
# while one busy loop per core keeps every core loaded, so that a test that leans on the
# wall clock (a rate, a frame time, a deadline) fails here rather than on a busy CI
# machine. Prints the load average and the wall time at the end; the busy loops are
# killed on any exit.
set -euo pipefail
cd "$(dirname "$0")/.."

cores="$(nproc)"
busy=()
stop_busy() {
    for pid in "${busy[@]}"; do
        kill "$pid" 2>/dev/null || true
    done
}
trap stop_busy EXIT
trap 'exit 130' INT TERM
for _ in $(seq "$cores"); do
    sh -c 'while :; do :; done' &
    busy+=("$!")
done
echo "test-under-load: ${#busy[@]} busy loops on $cores cores" >&2

start="$(date +%s)"
status=0
bash scripts/test.sh "$@" || status=$?
end="$(date +%s)"
echo "test-under-load: exit $status after $((end - start)) s; $(uptime | sed 's/.*load/load/')" >&2
exit "$status"
