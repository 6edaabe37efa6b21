#!/usr/bin/env bash
# Makes the orientation-set figures of docs/results.md ("Orientation sets"): mow workspace
# over positions and tilt envelopes of 5, 10, 15 and 20 deg (torsion +/- the same), 5 deg
# angle steps, on the long-crank hexapod and the hexaglide, then a markdown table of their
# total-orientation and inclusion volumes (summary.json's orientation_set) on stdout; the
# same figures to docs/data/orientation_envelopes.csv, the hexapod's coverage at 20 deg in
# the plane of positions where maximal and traditional differ most to
# docs/data/hexapod_long_coverage_20deg_slice.csv, and both drawn by plot_orientation.py into
# docs/images/orientation_envelopes.png.
# Working modes: the start's and the six one IKP branch away from it, which keeps the eight
# runs to minutes (all 64 at 20 deg take 6 min on the hexapod alone: docs/results.md).
# Needs a build (scripts/run_tests.sh first).
source "$(dirname "${BASH_SOURCE[0]}")/common.sh"
MOW="${WS}/devel/lib/maximal_workspace/mow"
OUT=$(mktemp -d /tmp/mow_orientation_XXXXXX)
trap 'rm -rf "${OUT}"' EXIT
HEXAPOD_MODES=nnnnnn,pnnnnn,npnnnn,nnpnnn,nnnpnn,nnnnpn,nnnnnp
HEXAGLIDE_MODES=ppnnpp,npnnpp,pnnnpp,pppnpp,ppnppp,ppnnnp,ppnnpn
for degrees in 5 10 15 20; do
  tilt=$(/usr/bin/python3 -c "import math; print(math.radians(${degrees}))")
  step=$(/usr/bin/python3 -c "import math; print(math.radians(5))")
  "${MOW}" workspace --robot "${REPO}/config/hexapod_6rss_long.yaml" --step 0.02 --tilt-max "${tilt}" \
    --torsion "-${tilt},${tilt}" --angle-step "${step}" --modes "${HEXAPOD_MODES}" --no-cache \
    --out "${OUT}/hexapod_${degrees}" --quiet > /dev/null
  # The box about the rails' middle: the safety box reaches below the rails, where the cones
  # block every pose.
  "${MOW}" workspace --robot "${REPO}/config/hexaglide_6pss.yaml" --step 0.02 --bounds -0.4,0.4,-0.2,0.2,0.1,0.5 \
    --tilt-max "${tilt}" --torsion "-${tilt},${tilt}" --angle-step "${step}" --modes "${HEXAGLIDE_MODES}" --no-cache \
    --out "${OUT}/hexaglide_${degrees}" --quiet > /dev/null
done
/usr/bin/python3 - "${OUT}" "${REPO}/docs/data" <<'PYTHON'
import csv, json, sys
out, data = sys.argv[1], sys.argv[2]
print("| robot | tilt and torsion | AM | total-orientation: maximal | traditional | maximal / traditional | inclusion: maximal | traditional | analysis |")
print("|---|---|---|---|---|---|---|---|---|")
with open(f"{data}/orientation_envelopes.csv", "w", newline="") as table:
    rows = csv.writer(table)
    rows.writerow(["robot", "envelope_deg", "sign", "total_orientation_maximal", "total_orientation_traditional",
                   "inclusion_maximal", "inclusion_traditional", "seconds"])
    for robot in ("hexapod", "hexaglide"):
        for degrees in (5, 10, 15, 20):
            s = json.load(open(f"{out}/{robot}_{degrees}/summary.json"))
            for am in s["orientation_set"]["assembly_modes"]:
                m, t = am["maximal"], am["traditional"]
                if m["inclusion_volume"] == 0:
                    continue
                ratio = m["total_orientation_volume"] / t["total_orientation_volume"] if t["total_orientation_volume"] else float("nan")
                print(f"| {robot} | {degrees} deg | {'+' if am['sign'] > 0 else '-'} | {m['total_orientation_volume']:.6f} | "
                      f"{t['total_orientation_volume']:.6f} | {ratio:.2f} | {m['inclusion_volume']:.6f} | "
                      f"{t['inclusion_volume']:.6f} | {s['seconds']['total']:.1f} s |")
                rows.writerow([robot, degrees, am["sign"], m["total_orientation_volume"], t["total_orientation_volume"],
                               m["inclusion_volume"], t["inclusion_volume"], round(s["seconds"]["total"], 1)])
with open(f"{out}/hexapod_20/coverage.csv") as source:
    rows = list(csv.DictReader(source))
gain = {}
for row in rows:
    gain[row["z"]] = gain.get(row["z"], 0.0) + float(row["maximal_negative"]) - float(row["traditional_negative"])
plane = max(gain, key=gain.get)
with open(f"{data}/hexapod_long_coverage_20deg_slice.csv", "w", newline="") as slice_file:
    writer = csv.DictWriter(slice_file, fieldnames=list(rows[0].keys()))
    writer.writeheader()
    writer.writerows(row for row in rows if row["z"] == plane)
PYTHON
/usr/bin/python3 "${REPO}/scripts/plot_orientation.py" "${REPO}/docs/data/orientation_envelopes.csv" \
  "${REPO}/docs/data/hexapod_long_coverage_20deg_slice.csv" "${REPO}/docs/images/orientation_envelopes.png"
