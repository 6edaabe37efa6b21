#!/usr/bin/env bash
# Time and peak memory of the whole analysis, dense and adaptive, against the step
# (docs/benchmarks.md, "Scaling to millimetres"): builds bench_workspace in a separate
# workspace, runs the sweep into docs/data/scaling.csv, and draws docs/images/scaling.png.
# About 40 minutes on 2 cores; the dense analysis stops at 2 mm (about 7 GB there).
# This virtual machine's speed drifts by up to 1.7x within an hour, so the one-core batch
# classifier rate is measured before and after the sweep, as a yardstick.
source "$(dirname "$0")/common.sh"
export MOW_WS=${MOW_WS:-/tmp/ws_bench}
WS=${MOW_WS}
mow_build bench_workspace bench_pose_analysis
BENCH="${WS}/devel/lib/maximal_workspace/bench_workspace"
OUT="${REPO}/docs/data"
mkdir -p "${OUT}"
cd "${REPO}"
yardstick() {
  "${WS}/devel/lib/maximal_workspace/bench_pose_analysis" --benchmark_filter='ClassifierBatch$' \
    --benchmark_repetitions=3 --benchmark_report_aggregates_only=true 2>/dev/null | grep median
}
echo "yardstick before: $(yardstick)"
parts=()
run() {  # run NAME bench-arguments...
  local part="/tmp/scaling_$1.csv"
  shift
  "${BENCH}" "$@" --csv "${part}"
  parts+=("${part}")
}
run small --method dense,adaptive --step 0.01,0.007,0.005,0.004,0.003 --repetitions 3
run adaptive_2mm --method adaptive --step 0.0025,0.002 --repetitions 3
run dense_2mm --method dense --step 0.0025,0.002 --repetitions 1
run adaptive_1mm --method adaptive --step 0.0015,0.001 --repetitions 1
# One header, then every part's rows.
{ head -n 1 "${parts[0]}"; for part in "${parts[@]}"; do tail -n +2 "${part}"; done; } > "${OUT}/scaling.csv"
echo "yardstick after: $(yardstick)"
/usr/bin/python3 "${REPO}/scripts/plot_scaling.py" "${OUT}/scaling.csv" "${REPO}/docs/images/scaling.png"
