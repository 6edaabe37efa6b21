#!/usr/bin/env bash
# Designs per minute of mow sweep on one machine (docs/benchmarks.md, "Design studies:
# threads and MPI ranks"): config/studies/delta_like_rods_5mm.yaml (81 designs, every one
# analysed) at 10 mm and at 5 mm, under each scheduling below, ROUNDS times (default 3).
# A round runs every scheduling once, so that a busy spell of the machine spreads over all
# of them. The time is the whole command's wall time, mpirun's start included; the table
# gives the medians. Before each run the load average and the busiest processes are
# printed: a run beside other work shows. About 20 minutes on 2 cores.
source "$(dirname "${BASH_SOURCE[0]}")/common.sh"
MOW=${MOW:-${WS}/devel/lib/maximal_workspace/mow}
ROUNDS=${ROUNDS:-3}
STEPS=${STEPS:-0.01 0.005}
# Open MPI refuses to start as root without both.
export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1
# Each: the launcher (none: mow alone) | mow sweep's own options. mpirun binds each rank to
# a core unless it oversubscribes them: a rank analysing on two threads needs --bind-to none.
SCHEDULINGS=("|--jobs 1" "|--jobs 2" "mpirun -np 2|" "mpirun -np 2 --bind-to none|--jobs 2" "mpirun -np 3 --oversubscribe|")
scratch=$(mktemp -d /tmp/benchmark_sweep_XXXXXX)
trap 'rm -rf "${scratch}"' EXIT
times="${scratch}/times.txt"

for step in ${STEPS}; do
  # The study at this step, its robot named by an absolute path from the scratch folder.
  study="${scratch}/rods_${step}.yaml"
  sed -e "s#^robot: .*#robot: ${REPO}/config/delta_like.yaml#" -e "s#^  step: .*#  step: ${step}#" \
    "${REPO}/config/studies/delta_like_rods_5mm.yaml" > "${study}"
  for ((round = 1; round <= ROUNDS; ++round)); do
    for scheduling in "${SCHEDULINGS[@]}"; do
      launcher=${scheduling%%|*} options=${scheduling#*|}
      busiest=$(top -b -n 2 -d 0.5 | awk '/^ *PID/ { frame++; next } frame == 2 && n++ < 2 { printf "%s %s%%; ", $12, $9 }')
      echo "step ${step}, round ${round}, ${launcher:-mow} ${options}: load $(cut -d' ' -f1-3 /proc/loadavg); busiest: ${busiest}"
      started=$(date +%s.%N)
      # shellcheck disable=SC2086 # the launcher and options are words
      ${launcher} "${MOW}" sweep --study "${study}" --out "${scratch}/run.csv" --force --quiet ${options} > "${scratch}/run.out"
      ended=$(date +%s.%N)
      grep "^results:" "${scratch}/run.out" | sed 's/^/  /'
      echo "${step}|${launcher:-mow alone}|${options}|$(awk "BEGIN { print ${ended} - ${started} }")" >> "${times}"
    done
  done
done

/usr/bin/python3 - "${times}" <<'PYTHON'
import statistics
import sys
from collections import defaultdict

DESIGNS = 81
runs = defaultdict(list)
for line in open(sys.argv[1]):
    step, launcher, options, seconds = line.rstrip("\n").split("|")
    runs[(float(step), launcher, options)].append(float(seconds))
print("\n| step | scheduling | runs (s) | median (s) | designs per minute |")
print("|---|---|---|---|---|")
for (step, launcher, options), seconds in runs.items():
    median = statistics.median(seconds)
    print(f"| {step * 1000:g} mm | {launcher} {options} | {', '.join(f'{s:.1f}' for s in seconds)} | {median:.1f} | "
          f"{60 * DESIGNS / median:.0f} |")
PYTHON
