#!/usr/bin/env bash
# Makes the figures of docs/results.md: mow workspace on the delta-like robot at 20, 10, 5
# and 2 mm, on the 5R at 1 mm, on the 6-RSS hexapod at 2 mm, on the tricylinder and on the
# robots with limits (certified volumes), then tables from their
# summary.json files (markdown on stdout), the margin sweep of margin_sensitivity.sh and
# the robots with limits of limits_results.sh.
# Needs a build (scripts/setup_and_run.sh or scripts/run_tests.sh first).
source "$(dirname "${BASH_SOURCE[0]}")/common.sh"
MOW="${WS}/devel/lib/maximal_workspace/mow"
OUT=$(mktemp -d /tmp/mow_results_XXXXXX)
trap 'rm -rf "${OUT}"' EXIT
run() {  # name robot-file step
  "${MOW}" workspace --robot "${REPO}/$2" --step "$3" --no-cache --out "${OUT}/$1" --quiet > /dev/null
}
run delta_20mm config/delta_like.yaml 0.02
run delta_10mm config/delta_like.yaml 0.01
run delta_5mm config/delta_like.yaml 0.005
run delta_2mm config/delta_like.yaml 0.002
run five_bar_1mm config/five_bar.yaml 0.001
run hexapod_2mm config/hexapod_6rss.yaml 0.002
run tricylinder_10mm test/robots/tricylinder.yaml 0.01
run tricylinder_5mm test/robots/tricylinder.yaml 0.005
run tricylinder_2mm test/robots/tricylinder.yaml 0.002
run limited_5mm config/delta_like_limited.yaml 0.005
run limited_2mm config/delta_like_limited.yaml 0.002
run linear_2mm config/linear_delta.yaml 0.002
run rotary_2mm config/rotary_delta.yaml 0.002
/usr/bin/python3 - "${OUT}" <<'PYTHON'
import json, math, sys
out = sys.argv[1]
load = lambda name: json.load(open(f"{out}/{name}/summary.json"))
pct = lambda x: f"{100 * x:.1f} %"

print("### Delta-like robot: convergence with the step\n")
print("| step | voxels | workspace (m^3) | AM | maximal | traditional | reachable from start | regions (debris) | transitions | groups |")
print("|---|---|---|---|---|---|---|---|---|---|")
for name in ("delta_20mm", "delta_10mm", "delta_5mm", "delta_2mm"):
    s = load(name)
    for am in s["assembly_modes"]:
        print(f"| {s['grid']['steps'][0] * 1000:g} mm | {s['workspace']['voxels']} | {s['workspace']['volume']:.4f} | "
              f"{'+' if am['sign'] > 0 else '-'} | {am['maximal_volume']:.4f} ({pct(am['maximal_fraction'])}) | "
              f"{am['traditional_volume']:.4f} ({pct(am['traditional_fraction'])}) | "
              f"{am['reachable_volume']:.4f} ({pct(am['reachable_fraction'])}) | {am['regions']} ({am['debris_regions']}) | "
              f"{am['transitions']} | {am['components']} |")

for name in ("delta_20mm", "delta_10mm", "delta_5mm", "delta_2mm"):
    s = load(name)
    print(f"\n### Delta-like robot at {s['grid']['steps'][0] * 1000:g} mm: regions per working mode and sign\n")
    print("| working mode | regions + (debris) | volume + (m^3) | regions - (debris) | volume - (m^3) |")
    print("|---|---|---|---|---|")
    for m in s["volumes_per_mode"]:
        p, n = m["positive"], m["negative"]
        print(f"| {m['mode']} | {p['regions']} ({p['debris']}) | {p['volume']:.4f} | {n['regions']} ({n['debris']}) | {n['volume']:.4f} |")
    singular = s["singularity_map"]
    print(f"\nStart in {s['start_mode']}; {s['transition_points']} transition points; "
          f"{singular['ikp_boundary_faces']} IKP boundary faces ({singular['ikp_chain_entries']} counted once per "
          f"limiting chain); {singular['dkp_voxel_entries']} DKP-singular voxel entries; "
          f"computed in {s['seconds']['total']:.2f} s.")

s = load("five_bar_1mm")
def lens(r1, r2, d):
    if d >= r1 + r2: return 0.0
    if d <= abs(r1 - r2): return math.pi * min(r1, r2) ** 2
    a = r1 * r1 * math.acos((d * d + r1 * r1 - r2 * r2) / (2 * d * r1))
    b = r2 * r2 * math.acos((d * d + r2 * r2 - r1 * r1) / (2 * d * r2))
    return a + b - 0.5 * math.sqrt((-d + r1 + r2) * (d + r1 - r2) * (d - r1 + r2) * (d + r1 + r2))
closed = lens(.45, .45, .2) - 2 * lens(.45, .05, .2) + lens(.05, .05, .2)
area = s["workspace"]["volume"]
print("\n### Planar 5R at 1 mm\n")
print(f"Area {area:.6f} m^2 against the closed form {closed:.6f} m^2 (two annuli 0.05-0.45 m about bases 0.2 m apart): "
      f"{100 * (area - closed) / closed:+.3f} %. {len(s['working_modes'])} working modes ({' '.join(s['working_modes'])}), "
      f"start in {s['start_mode']}, {s['transition_points']} transition points.\n")
print("| AM | maximal | traditional | reachable from start | regions (debris) | transitions | groups |")
print("|---|---|---|---|---|---|---|")
for am in s["assembly_modes"]:
    print(f"| {'+' if am['sign'] > 0 else '-'} | {am['maximal_volume']:.4f} m^2 ({pct(am['maximal_fraction'])}) | "
          f"{am['traditional_volume']:.4f} m^2 ({pct(am['traditional_fraction'])}) | "
          f"{am['reachable_volume']:.4f} m^2 ({pct(am['reachable_fraction'])}) | {am['regions']} ({am['debris_regions']}) | "
          f"{am['transitions']} | {am['components']} |")
print("\n| working mode | regions + (debris) | area + (m^2) | regions - (debris) | area - (m^2) |")
print("|---|---|---|---|---|")
for m in s["volumes_per_mode"]:
    p, n = m["positive"], m["negative"]
    print(f"| {m['mode']} | {p['regions']} ({p['debris']}) | {p['volume']:.4f} | {n['regions']} ({n['debris']}) | {n['volume']:.4f} |")

s = load("hexapod_2mm")
print(f"\n### 6-RSS hexapod at 2 mm, platform level\n")
print(f"Workspace {s['workspace']['volume']:.6f} m^3 ({s['workspace']['voxels']} voxels), "
      f"{len(s['working_modes'])} working modes (det J_DKP by {s['det_method']}), start in {s['start_mode']}, "
      f"{s['transition_points']} transition points, {s['singularity_map']['dkp_voxel_entries']} DKP-singular voxel "
      f"entries; computed in {s['seconds']['total']:.2f} s.\n")
print("| AM | maximal | traditional | reachable from start | regions (debris) | transitions | groups |")
print("|---|---|---|---|---|---|---|")
for am in s["assembly_modes"]:
    print(f"| {'+' if am['sign'] > 0 else '-'} | {am['maximal_volume']:.6f} m^3 ({pct(am['maximal_fraction'])}) | "
          f"{am['traditional_volume']:.6f} m^3 ({pct(am['traditional_fraction'])}) | "
          f"{am['reachable_volume']:.6f} m^3 ({pct(am['reachable_fraction'])}) | {am['regions']} ({am['debris_regions']}) | "
          f"{am['transitions']} | {am['components']} |")

print("\n### Certified volumes\n")
print("The exact volume lies in [inner, inner + boundary] (docs/kinematics.md, \"Certified volumes\"); "
      "*sampled*: the cells' volume by their centres, the figures above. The tricylinder "
      "(test/robots/tricylinder.yaml) has a closed form, 8 (2 - sqrt 2) 0.3^3 = "
      f"{8 * (2 - math.sqrt(2)) * 0.027:.6f} m^3.\n")
print("| robot | step | set | sampled (m^3) | certified (m^3) | boundary / sampled | poses tested / workspace voxels |")
print("|---|---|---|---|---|---|---|")
def bounds(b):
    return f"[{b['inner_volume']:.4f}, {b['inner_volume'] + b['boundary_volume']:.4f}]"
for name in ("delta_20mm", "delta_10mm", "delta_5mm", "delta_2mm", "tricylinder_10mm", "tricylinder_5mm", "tricylinder_2mm",
             "limited_5mm", "limited_2mm", "linear_2mm", "rotary_2mm", "five_bar_1mm", "hexapod_2mm"):
    s = load(name)
    w = s["workspace"]
    rows = [("workspace", w["volume"], w["bounds"])]
    for am in s["assembly_modes"]:
        sign = "+" if am["sign"] > 0 else "-"
        rows.append((f"maximal {sign}", am["maximal_volume"], am["maximal_bounds"]))
        rows.append((f"traditional {sign}", am["traditional_volume"], am["traditional_bounds"]))
    for i, (label, volume, b) in enumerate(rows):
        ratio = pct(b["boundary_volume"] / volume) if volume > 0 else "-"
        poses = pct(w["poses_tested"] / w["voxels"]) if i == 0 else ""
        print(f"| {s['robot']['name'] if i == 0 else ''} | {s['grid']['steps'][0] * 1000:g} mm | {label} | {volume:.4f} | "
              f"{bounds(b)} | {ratio} | {poses} |")
PYTHON
# The same robots under dexterity margins (docs/results.md, "Sensitivity to the margin").
"$(dirname "${BASH_SOURCE[0]}")/margin_sensitivity.sh"
# The robots with limits (docs/results.md, "Robots with limits").
"$(dirname "${BASH_SOURCE[0]}")/limits_results.sh"
