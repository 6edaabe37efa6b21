#!/usr/bin/env bash
# How the results depend on the dexterity margin (mow workspace --margin, docs/kinematics.md),
# on the three shipped robots:
#  - margins 0, 1e-4, 1e-3, 1e-2 at steps 20, 10, 5, 2 mm: one markdown table per robot on
#    stdout (margin 0 also shows how far the exact figures still move with the step);
#  - margins 0 and 1e-6 to 3e-2 at 5 mm: docs/images/margin_sensitivity.png (plot_margin.py).
# Every run is one row per assembly mode in docs/data/margin_sensitivity.csv. Called by
# workspace_results.sh; about 1 min on 2 cores, most of it the delta-like robot at 2 mm
# (10 s per margin). Needs a build.
source "$(dirname "${BASH_SOURCE[0]}")/common.sh"
MOW="${WS}/devel/lib/maximal_workspace/mow"
OUT=$(mktemp -d /tmp/mow_margin_XXXXXX)
trap 'rm -rf "${OUT}"' EXIT
ROBOTS=(delta_like five_bar hexapod_6rss)
TABLE_MARGINS=(0 1e-4 1e-3 1e-2)
TABLE_STEPS=(0.02 0.01 0.005 0.002)
CURVE_MARGINS=(0 1e-6 1e-5 3e-5 1e-4 3e-4 1e-3 3e-3 1e-2 3e-2)
CURVE_STEP=0.005
run() {  # robot step margin; the table and the curve share their 5 mm runs, so each runs once
  local dir="${OUT}/$1_$2_$3"
  [ -d "${dir}" ] || "${MOW}" workspace --robot "${REPO}/config/$1.yaml" --step "$2" --margin "$3" \
    --no-cache --out "${dir}" --quiet > /dev/null
}
for robot in "${ROBOTS[@]}"; do
  for step in "${TABLE_STEPS[@]}"; do
    for margin in "${TABLE_MARGINS[@]}"; do run "${robot}" "${step}" "${margin}"; done
  done
  for margin in "${CURVE_MARGINS[@]}"; do run "${robot}" "${CURVE_STEP}" "${margin}"; done
done
mkdir -p "${REPO}/docs/data" "${REPO}/docs/images"
CSV="${REPO}/docs/data/margin_sensitivity.csv"
/usr/bin/python3 - "${OUT}" "${CSV}" "${ROBOTS[*]}" "${TABLE_MARGINS[*]}" "${TABLE_STEPS[*]}" <<'PYTHON'
import csv, glob, json, sys
out, csv_path, robots, margins, steps = sys.argv[1], sys.argv[2], *(a.split() for a in sys.argv[3:6])
margins, steps = [float(m) for m in margins], [float(s) for s in steps]
COLUMNS = ["robot", "margin", "step_m", "sign", "workspace_volume", "maximal_volume", "traditional_volume",
           "reachable_volume", "maximal_fraction", "traditional_fraction", "reachable_fraction", "regions",
           "debris_regions", "transitions", "groups"]

rows = []
for path in glob.glob(f"{out}/*/summary.json"):
    s = json.load(open(path))
    for am in s["assembly_modes"]:
        rows.append({"robot": s["robot"]["name"], "margin": s["options"]["margin"], "step_m": s["grid"]["steps"][0],
                     "sign": "+" if am["sign"] > 0 else "-", "workspace_volume": s["workspace"]["volume"],
                     "groups": am["components"], **{c: am[c] for c in COLUMNS[5:14]}})
# Robots in the order given, coarse steps first, then margins up, + before -.
rows.sort(key=lambda r: (robots.index(r["robot"]), -r["step_m"], r["margin"], r["sign"] != "+"))
with open(csv_path, "w", newline="") as target:
    writer = csv.DictWriter(target, COLUMNS)
    writer.writeheader()
    # 10 significant digits: enough for every figure, without the sums' binary rounding noise.
    writer.writerows({k: f"{v:.10g}" if isinstance(v, float) else v for k, v in r.items()} for r in rows)

pct = lambda x: f"{100 * x:.1f} %"
row = {(r["robot"], r["margin"], r["step_m"], r["sign"]): r for r in rows}
for robot in robots:
    print(f"\n### {robot}: margin against step\n")
    print("| margin | step | traditional + | reachable + | groups + | traditional - | reachable - | groups - |")
    print("|---|---|---|---|---|---|---|---|")
    for margin in margins:
        for step in steps:
            cells = [f"{margin:g}" if margin else "0 (exact)", f"{step * 1000:g} mm"]
            for sign in "+-":
                r = row[robot, margin, step, sign]
                cells += [pct(r["traditional_fraction"]), pct(r["reachable_fraction"]), str(r["groups"])]
            print("| " + " | ".join(cells) + " |")
PYTHON
/usr/bin/python3 "${REPO}/scripts/plot_margin.py" "${CSV}" "${REPO}/docs/images/margin_sensitivity.png" "${CURVE_STEP}"
