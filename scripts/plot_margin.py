#!/usr/bin/env python3
"""Draws, per shipped robot and assembly mode, the share of the workspace reachable from
the start (solid) and the traditional workspace (dashed) against the dexterity margin,
from the CSV that margin_sensitivity.sh writes. The x axis is logarithmic; margin 0 (exact
signs) has no place on it and is drawn apart at its left edge.

usage: plot_margin.py MARGIN.csv OUT.png [STEP_M]
STEP_M picks the rows of one grid step (default 0.005). Needs Debian's python3-matplotlib
(apt-get install -y --no-install-recommends python3-matplotlib); run it with /usr/bin/python3."""
import csv
import sys

try:
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from matplotlib.lines import Line2D
except ImportError as error:
    sys.exit(f"plot_margin.py: {error}; install Debian's python3-matplotlib and run with /usr/bin/python3")

ROBOTS = {"delta_like": ("delta-like (x y z)", "tab:blue"),
          "five_bar": ("planar 5R (x y)", "tab:orange"),
          "hexapod_6rss": ("6-RSS hexapod (fixed orientation)", "tab:green")}
MARKERS = {"+": "^", "-": "v"}
BREAK = 97.5  # %: the border between the two panels


def main():
    if len(sys.argv) not in (3, 4):
        sys.exit(__doc__)
    step = float(sys.argv[3]) if len(sys.argv) == 4 else 0.005
    with open(sys.argv[1], newline="") as source:
        rows = [r for r in csv.DictReader(source) if abs(float(r["step_m"]) - step) < 1e-9]
    margins = sorted({float(r["margin"]) for r in rows} - {0.0})
    if not margins:
        sys.exit(f"plot_margin.py: no rows with a margin > 0 at step {step:g} m in {sys.argv[1]}")
    # Margin 0 goes one decade left of the smallest margin, past a dotted line marking the gap.
    exact_x = margins[0] / 10
    # Most curves sit within a few points of 100 %, where a single axis would stack them on
    # one another: the top panel magnifies that band, the bottom one shows the rest.
    figure, (top, bottom) = plt.subplots(2, 1, sharex=True, figsize=(10, 6.1),
                                         gridspec_kw={"height_ratios": [1, 1.6], "hspace": 0.06})
    figure.subplots_adjust(left=0.08, right=0.98, top=0.93, bottom=0.12)
    drawn = [r for r in rows if float(r["reachable_fraction"]) > 0]
    low = 100 * min(min(float(r["reachable_fraction"]), float(r["traditional_fraction"])) for r in drawn)
    top.set_ylim(BREAK, 100.3)
    bottom.set_ylim(min(low, BREAK) - 2, BREAK)
    notes = {robot: [] for robot in ROBOTS}  # what a legend entry says so that no hidden curve seems missing
    for robot, (label, colour) in ROBOTS.items():
        previous = None
        for sign, marker in MARKERS.items():
            curve = sorted((float(r["margin"]), 100 * float(r["reachable_fraction"]),
                            100 * float(r["traditional_fraction"]))
                           for r in drawn if r["robot"] == robot and r["sign"] == sign)
            # An assembly mode with no pose at all (the hexapod's +) would only be a line at 0.
            if not curve:
                notes[robot].append(f"no {sign} poses")
                continue
            if curve == previous:
                notes[robot].append("+ and - coincide")
            if all(p[1] == p[2] for p in curve) and "traditional = reachable" not in notes[robot]:
                notes[robot].append("traditional = reachable")
            previous = curve
            style = dict(color=colour, markersize=6, markerfacecolor="none" if sign == "-" else colour)
            for axis in (top, bottom):
                lo, hi = axis.get_ylim()
                for column, line in ((1, "-"), (2, "--")):
                    # No line across the gap: nothing was measured between 0 and the smallest margin.
                    axis.plot([p[0] for p in curve if p[0] > 0], [p[column] for p in curve if p[0] > 0], line,
                              color=colour)
                    # Markers only inside the panel: a point just across the border would show half a marker.
                    shown = [(p[0] or exact_x, p[column]) for p in curve if lo <= p[column] <= hi]
                    axis.plot([x for x, _ in shown], [y for _, y in shown], marker=marker, linestyle="none", **style)
    top.spines["bottom"].set_visible(False)
    bottom.spines["top"].set_visible(False)
    top.tick_params(bottom=False)
    for axis in (top, bottom):
        axis.set_xscale("log")
        axis.axvline((exact_x * margins[0]) ** 0.5, color="grey", linestyle=":", linewidth=1)
        axis.grid(True, alpha=0.3)
    ticks = [exact_x] + [10.0 ** e for e in range(-9, 2) if margins[0] <= 10.0 ** e <= margins[-1]]
    bottom.set_xticks(ticks)
    bottom.set_xticklabels(["exact\n(0)"] + [f"{t:g}" for t in ticks[1:]])
    bottom.minorticks_off()
    bottom.set_xlim(exact_x / 2, margins[-1] * 2)
    bottom.set_xlabel("margin M: cells with |singularity measure| < M count as singular")
    figure.supylabel("share of the workspace (%)", x=0.01)
    # Two legends where the curves leave room: robots under the 100 % lines, styles under the
    # delta-like robot's traditional + at the left.
    top.legend(handles=[Line2D([], [], color=colour, linewidth=4, label=f"{label}\n{'; '.join(notes[robot])}".strip())
                        for robot, (label, colour) in ROBOTS.items() if any(r["robot"] == robot for r in drawn)],
               loc="lower right", fontsize=9)
    bottom.legend(handles=[Line2D([], [], color="black", linestyle="-", label="reachable from start"),
                           Line2D([], [], color="black", linestyle="--", label="traditional"),
                           Line2D([], [], color="black", marker="^", linestyle="none", label="assembly mode +"),
                           Line2D([], [], color="black", marker="v", markerfacecolor="none", linestyle="none",
                                  label="assembly mode -")], loc="lower left", fontsize=9)
    top.set_title(f"Effect of the dexterity margin, {step * 1000:g} mm grid "
                  f"(top panel: {BREAK:g} to 100 % magnified)", fontsize=12)
    figure.savefig(sys.argv[2], dpi=90)


if __name__ == "__main__":
    main()
