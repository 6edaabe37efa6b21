#!/usr/bin/env bash
# Time and peak memory of the whole analysis against the step (docs/benchmarks.md,
# "Scaling to millimetres"), and the engine against the one it replaced, in one run:
#  1. builds bench_workspace of this checkout, and of BEFORE_REF (default cd5856a, the last
#     commit with the two pipelines) in a worktree of its own;
#  2. runs both at 2 mm and 1 mm, alternating, and prints the medians and their ratios
#     (this virtual machine's speed drifts by up to 2x within an hour: only ratios of one
#     run compare);
#  3. sweeps this engine from 10 mm to 1 mm into docs/data/scaling.csv and draws
#     docs/images/scaling.png with fitted exponents.
# About 15 minutes on 2 cores. Set SKIP_BEFORE=1 to skip 1 and 2 for the old engine.
export MOW_WS=${MOW_WS:-/tmp/ws_bench}
source "$(dirname "$0")/common.sh"
BEFORE_REF=${BEFORE_REF:-cd5856a}
OLD_WS=/tmp/ws_bench_before
OLD_TREE=/tmp/mow_before_tree
OUT="${REPO}/docs/data"
mkdir -p "${OUT}"
cd "${REPO}"

mow_build bench_workspace
NEW="${WS}/devel/lib/maximal_workspace/bench_workspace"
if [ "${SKIP_BEFORE:-0}" != 1 ]; then
  if [ ! -d "${OLD_TREE}" ]; then git worktree add --detach "${OLD_TREE}" "${BEFORE_REF}"; fi
  (export MOW_WS=${OLD_WS}; source "${OLD_TREE}/scripts/common.sh" && mow_build bench_workspace)
  OLD="${OLD_WS}/devel/lib/maximal_workspace/bench_workspace"
  # Columns by name, as the two programs order them differently.
  column() {  # column CSV NAME: the value of NAME in the CSV's last row
    /usr/bin/python3 -c "import csv,sys; r=list(csv.DictReader(open(sys.argv[1])))[-1]; print(r[sys.argv[2]])" "$1" "$2"
  }
  compare() {  # compare STEP ROUNDS
    local old_t=() new_t=() old_m=() new_m=()
    for ((round = 0; round < $2; ++round)); do
      "${OLD}" --method adaptive --step "$1" --repetitions 1 --csv /tmp/before.csv > /dev/null
      "${NEW}" --step "$1" --repetitions 1 --csv /tmp/after.csv > /dev/null
      old_t+=("$(column /tmp/before.csv process_s)") old_m+=("$(column /tmp/before.csv peak_MiB)")
      new_t+=("$(column /tmp/after.csv process_s)") new_m+=("$(column /tmp/after.csv peak_MiB)")
    done
    /usr/bin/python3 - "$1" "${old_t[*]}" "${new_t[*]}" "${old_m[*]}" "${new_m[*]}" <<'PYTHON'
import statistics, sys
step = float(sys.argv[1]) * 1000
old_t, new_t, old_m, new_m = ([float(v) for v in a.split()] for a in sys.argv[2:6])
mt, nt, mm, nm = (statistics.median(v) for v in (old_t, new_t, old_m, new_m))
print(f"{step:g} mm, {len(old_t)} alternating runs: before {mt:.2f} s {mm:.0f} MiB, after {nt:.2f} s {nm:.0f} MiB; "
      f"time x{nt / mt:.2f}, memory x{nm / mm:.2f}")
PYTHON
  }
  compare 0.002 3
  compare 0.001 1
fi
parts=()
run() {  # run NAME bench-arguments...
  local part="/tmp/scaling_$1.csv"
  shift
  "${NEW}" "$@" --csv "${part}" > /dev/null
  parts+=("${part}")
}
run fine --step 0.01,0.007,0.005,0.004,0.003,0.0025,0.002 --repetitions 3
run finest --step 0.0015,0.001 --repetitions 1
# One header, then every part's rows.
{ head -n 1 "${parts[0]}"; for part in "${parts[@]}"; do tail -n +2 "${part}"; done; } > "${OUT}/scaling.csv"
/usr/bin/python3 "${REPO}/scripts/plot_scaling.py" "${OUT}/scaling.csv" "${REPO}/docs/images/scaling.png"
