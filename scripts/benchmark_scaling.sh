#!/usr/bin/env bash
# Time and peak memory of the whole analysis against the step (docs/benchmarks.md,
# "Scaling to millimetres"), and the engine against the one it replaced, in one run:
#  1. builds `mow` of this checkout, and of BEFORE_REF (default 4cdcc54, the engine issue
#     29 replaced) in a worktree of its own;
#  2. runs `mow workspace --step S --no-cache --quiet` of both at 2 mm (ROUNDS_2MM times,
#     default 3) and 1 mm (ROUNDS_1MM, default 1), alternating, under /usr/bin/time, and
#     prints the medians of wall time and peak memory and their ratios (this virtual
#     machine's speed drifts by up to 2x within an hour: only ratios of one run compare);
#  3. sweeps this engine's bench_workspace from 10 mm to 1 mm into docs/data/scaling.csv
#     and draws docs/images/scaling.png with fitted exponents.
# About 20 minutes on 2 cores, and the old engine's build. SKIP_BEFORE=1 skips 1 and 2
# for the old engine.
export MOW_WS=${MOW_WS:-/tmp/ws_bench}
source "$(dirname "$0")/common.sh"
BEFORE_REF=${BEFORE_REF:-4cdcc54}
OLD_WS=/tmp/ws_bench_before
OLD_TREE=/tmp/mow_before_tree
OUT="${REPO}/docs/data"
mkdir -p "${OUT}"
cd "${REPO}"

mow_build bench_workspace mow
NEW="${WS}/devel/lib/maximal_workspace/bench_workspace"
if [ "${SKIP_BEFORE:-0}" != 1 ]; then
  if [ ! -d "${OLD_TREE}" ]; then git worktree add --detach "${OLD_TREE}" "${BEFORE_REF}"; fi
  (export MOW_WS=${OLD_WS}; source "${OLD_TREE}/scripts/common.sh" && mow_build mow)
  ROBOT="${REPO}/config/delta_like.yaml"
  timed() {  # timed MOW STEP: "wall_s peak_KB" of one analysis
    /usr/bin/time -f "%e %M" -o /tmp/mow_timed.txt "$1" workspace --robot "${ROBOT}" --step "$2" --no-cache --quiet \
      > /dev/null
    cat /tmp/mow_timed.txt
  }
  compare() {  # compare STEP ROUNDS
    local old_t=() new_t=() old_m=() new_m=() figures
    for ((round = 0; round < $2; ++round)); do
      read -ra figures <<< "$(timed "${OLD_WS}/devel/lib/maximal_workspace/mow" "$1")"
      old_t+=("${figures[0]}") old_m+=("${figures[1]}")
      read -ra figures <<< "$(timed "${WS}/devel/lib/maximal_workspace/mow" "$1")"
      new_t+=("${figures[0]}") new_m+=("${figures[1]}")
    done
    /usr/bin/python3 - "$1" "${old_t[*]}" "${new_t[*]}" "${old_m[*]}" "${new_m[*]}" <<'PYTHON'
import statistics, sys
step = float(sys.argv[1]) * 1000
old_t, new_t, old_m, new_m = ([float(v) for v in a.split()] for a in sys.argv[2:6])
mt, nt, mm, nm = (statistics.median(v) for v in (old_t, new_t, old_m, new_m))
print(f"{step:g} mm, {len(old_t)} alternating runs: before {mt:.2f} s {mm / 1024:.0f} MiB "
      f"({' '.join(f'{v:.2f}' for v in old_t)}), after {nt:.2f} s {nm / 1024:.0f} MiB "
      f"({' '.join(f'{v:.2f}' for v in new_t)}); speed-up x{mt / nt:.2f}, memory x{nm / mm:.2f}")
PYTHON
  }
  compare 0.002 "${ROUNDS_2MM:-3}"
  compare 0.001 "${ROUNDS_1MM:-1}"
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
