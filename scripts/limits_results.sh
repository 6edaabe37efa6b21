#!/usr/bin/env bash
# Makes the robot-limits tables of docs/results.md: for each shipped robot with limits
# (config/delta_like_limited.yaml, linear_delta.yaml, rotary_delta.yaml), mow workspace
# with all its limits, with none, and with each kind alone (actuator ranges, joint cones,
# rods), at step STEP (default 0.005 m), on one thread. A variant whose box the limits
# alone bounded (a linear delta's rails) is given the full file's box. Markdown on stdout,
# with the classification's time per pose tested (what checking the limits costs the
# engine: docs/benchmarks.md).
# Needs a build (scripts/setup_and_run.sh or scripts/run_tests.sh first).
source "$(dirname "${BASH_SOURCE[0]}")/common.sh"
MOW="${WS}/devel/lib/maximal_workspace/mow"
OUT=$(mktemp -d /tmp/mow_limits_XXXXXX)
trap 'rm -rf "${OUT}"' EXIT
/usr/bin/python3 - "${MOW}" "${REPO}/config" "${OUT}" "${1:-0.005}" <<'PYTHON'
import copy, json, subprocess, sys
import yaml

mow, config, out, step = sys.argv[1], sys.argv[2], sys.argv[3], sys.argv[4]
KINDS = {"inputs": "actuator ranges", "cones": "joint cones", "rods": "rods (radius, clearance)"}


def variant(robot, keep):
    """The robot file keeping only the limits of the kinds in `keep`."""
    robot = copy.deepcopy(robot)
    if "rods" not in keep:
        robot.pop("clearance", None)
    for item in robot["inputs"]:
        if "inputs" not in keep:
            item.pop("limits", None)
    for chain in robot["chains"]:
        if "cones" not in keep:
            chain.pop("joint_limits", None)
        if "rods" not in keep:
            chain.pop("rod_radius", None)
    return robot


def analyse(name, robot, bounds=None):
    path = f"{out}/{name}.yaml"
    with open(path, "w") as f:
        yaml.safe_dump(robot, f)
    command = [mow, "workspace", "--robot", path, "--step", step, "--no-cache", "--quiet", "--threads", "1", "--out",
               f"{out}/{name}"]
    if bounds:
        command += ["--bounds", ",".join(f"{v:.10g}" for pair in bounds for v in pair)]
    done = subprocess.run(command, capture_output=True, text=True)
    if done.returncode != 0:
        return None, done.stderr.strip()
    return json.load(open(f"{out}/{name}/summary.json")), None


for file_name in ("delta_like_limited", "linear_delta", "rotary_delta"):
    robot = yaml.safe_load(open(f"{config}/{file_name}.yaml"))
    full, error = analyse(f"{file_name}_all", robot)
    if error:
        sys.exit(f"limits_results: {file_name}: {error}")
    runs = [("all limits", full)]
    for label, keep in [("none", set()), *[(f"{text} only", {kind}) for kind, text in KINDS.items()]]:
        summary, error = analyse(f"{file_name}_{'_'.join(sorted(keep)) or 'none'}", variant(robot, keep))
        if error and "unbounded" in error:
            summary, error = analyse(f"{file_name}_{'_'.join(sorted(keep)) or 'none'}_boxed", variant(robot, keep),
                                     full["grid"]["bounds"])
            label += " (in the full file's box)"
        if error:
            sys.exit(f"limits_results: {file_name}, {label}: {error}")
        runs.append((label, summary))
    none = runs[1][1]["workspace"]["volume"]
    print(f"\n#### {file_name} at {float(step) * 1000:g} mm (start in {full['start_mode']})\n")
    print("| limits | workspace (m^3) | removed | AM | maximal | traditional | reachable | regions | transitions "
          "| walls: actuator / cone / rods | ns per pose |")
    print("|---|---|---|---|---|---|---|---|---|---|---|")
    for label, s in runs:
        volume = s["workspace"]["volume"]
        walls = s["singularity_map"]
        wall_text = (f"{walls['actuator_limit_entries']} / {walls['joint_cone_entries']} / "
                     f"{walls['interference_entries']}")
        per_pose = 1e9 * s["seconds"]["classification"] / s["workspace"]["poses_tested"]
        for am in s["assembly_modes"]:
            share = lambda key: f"{am[key + '_volume']:.4f}"
            print(f"| {label} | {volume:.4f} | {100 * (1 - volume / none):.1f} % | {'+' if am['sign'] > 0 else '-'} | "
                  f"{share('maximal')} | {share('traditional')} | {share('reachable')} | {am['regions']} | "
                  f"{am['transitions']} | {wall_text} | {per_pose:.0f} |")
PYTHON
