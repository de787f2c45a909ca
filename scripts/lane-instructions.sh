#!/usr/bin/env bash
# Instructions the XPBD lane kernel executes per tet projection, counted by valgrind
# (issue 35, item 3): where they go, by a count that does not move with the machine's
# load. Fewer is not always faster (the kernel is held by its arithmetic units and the
# chains between them, not by how many instructions it issues), so time a change as well
# (`incise bench realtime`, interleaved). The sweep of
# config/intestine_pull_xpbd.ron on one thread for one frame (and the benchmark's two
# warm-up frames) runs under callgrind; the kernel's instructions are split by the part of
# the kernel they come from (reading the nodes into the lanes, the projection, writing
# them back) and by kind (arithmetic, stack moves, shuffles, ...). Needs valgrind, python3
# and addr2line (Debian: valgrind, python3, binutils); about a minute.
#
#   bash scripts/lane-instructions.sh                 # the AVX2 path (--cpu-kernel avx2-lanes)
#   bash scripts/lane-instructions.sh lanes blocks    # KERNEL SWEEP (valgrind has no AVX-512,
#                                                     # so `lanes` runs the AVX2 path too)
set -euo pipefail
cd "$(dirname "$0")/.."
kernel="${1:-avx2-lanes}"
sweep="${2:-blocks}"
for tool in valgrind python3 addr2line; do
    command -v "$tool" >/dev/null || {
        echo "lane-instructions: $tool is missing (Debian: apt-get install valgrind python3 binutils)" >&2
        exit 1
    }
done
cargo build --release --locked --quiet
bin=target/release/incise
work="$(mktemp -d)"
trap 'rm -rf "$work"' EXIT
valgrind --tool=callgrind --dump-instr=yes --callgrind-out-file="$work/cg.out" \
    "$bin" bench realtime --scene config/intestine_pull_xpbd.ron --cpu-kernel "$kernel" \
    --cpu-sweep "$sweep" --threads 1 --frames 1 --json >"$work/bench.json" 2>"$work/valgrind.log" || {
    tail -n 20 "$work/valgrind.log" >&2
    echo "lane-instructions: the benchmark failed under valgrind (its output above)" >&2
    exit 1
}
python3 - "$bin" "$work/cg.out" "$work/bench.json" <<'EOF'
import collections, json, re, subprocess, sys

binary, profile, bench = sys.argv[1:4]
KERNEL = "xpbd::lane_pass::project_run"  # the run functions the lane kernel is inlined into

# Executed instructions per address of the kernel (callgrind: `positions: instr line`).
counts, names, fn, pos, after_call = collections.Counter(), {}, "", 0, False
for line in open(profile):
    if line.startswith(("fn=", "cfn=")):
        m = re.match(r"c?fn=\((\d+)\)(?: (.*))?", line.strip())
        if m and m.group(2):
            names[m.group(1)] = m.group(2)
        if line.startswith("fn="):
            fn = names.get(m.group(1), "") if m else line[3:].strip()
        continue
    if line.startswith("calls="):
        after_call = True
        continue
    if not line[:1].isdigit() and line[:1] not in "+-*":
        continue
    cols = line.split()
    p = cols[0]
    if p.startswith("0x"):
        pos = int(p, 16)
    elif p[0] in "+-":
        pos += int(p[1:], 0) * (1 if p[0] == "+" else -1)
    elif p != "*":
        pos = int(p)
    if after_call:  # the callee's inclusive cost, not this instruction's
        after_call = False
        continue
    if KERNEL in fn and len(cols) > 2:
        counts[pos] += int(cols[2])
if not counts:
    sys.exit("lane-instructions: no instruction of the lane kernel was counted")

run = json.load(open(bench))
run = run[0] if isinstance(run, list) else run
projections = run["tets"] * run["substeps"] * (run["frames"] + run["warm_up_frames"])

# Each address's opcode and the functions it was inlined from (outermost first).
lo, hi = min(counts), max(counts) + 16
dis = subprocess.run(["objdump", "-d", "--no-show-raw-insn", f"--start-address={lo:#x}",
                      f"--stop-address={hi:#x}", binary], capture_output=True, text=True).stdout
ops = {int(m.group(1), 16): (m.group(2), m.group(3))
       for m in re.finditer(r"^\s+([0-9a-f]+):\s+(\S+)\s*(.*)$", dis, re.M)}
addrs = sorted(counts)
out = subprocess.run(["addr2line", "-a", "-i", "-f", "-C", "-e", binary] + [hex(a) for a in addrs],
                     capture_output=True, text=True).stdout.splitlines()
frames, cur = {}, None
for l in out:
    if l.startswith("0x"):
        cur = int(l, 16)
        frames[cur] = []
    elif ":" not in l or "::" in l:  # a function name line (locations are file:line)
        frames[cur].append(l.split("<")[0].split("::")[-1])

PARTS = {"load_nodes": "read the nodes", "project_rest_free_lanes": "project",
         "store_nodes": "write the nodes back", "finish_block": "write the nodes back"}

def part(a):
    for f in reversed(frames.get(a, [])):  # outermost first
        if f in PARTS:
            return PARTS[f]
    return "block loop, terms, multipliers"

def kind(op, args):
    if op.startswith("vmov") and "(%rsp" in args:
        return "stack store (spill)" if args.rstrip().endswith("(%rsp)") else "stack load (spill)"
    if op in ("vaddps", "vsubps", "vmulps", "vdivps", "vsqrtps", "vmaxps", "vminps"):
        return "arithmetic"
    if re.match(r"v(and|andn|or|xor|blendv|cmp\w*)ps$|vmovmskps", op):
        return "masks and selects"
    if re.match(r"v(unpck|shuf|insert|extract|movlh|movhl|perm|pinsr|pextr|punpck)", op):
        return "shuffles"
    if op.startswith("vbroadcast"):
        return "constants"
    if op.startswith("vmov"):
        return "other vector loads and stores"
    if op.startswith("j") or op in ("cmp", "test", "cmpl", "cmpq", "seta"):
        return "compares and branches"
    return "integer (addresses, indices)"

by_part, by_kind = collections.Counter(), collections.Counter()
for a, c in counts.items():
    op, args = ops.get(a, ("?", ""))
    by_part[part(a)] += c
    by_kind[kind(op, args)] += c
total = sum(counts.values())
print(f"{run['cpu_kernel']} on config/intestine_pull_xpbd.ron, 1 thread: "
      f"{total / projections:.1f} instructions per tet projection "
      f"({projections} projections, padding lanes included)")
for title, table in (("part", by_part), ("kind", by_kind)):
    print(f"\n| {title} | per tet | share |\n|---|---|---|")
    for k, v in table.most_common():
        print(f"| {k} | {v / projections:.1f} | {100 * v / total:.0f} % |")
EOF
