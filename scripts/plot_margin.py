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
          "hexapod_6rss": ("6-RSS hexapod (x y z, fixed orientation)", "tab:green")}
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
    figure, (top, bottom) = plt.subplots(2, 1, sharex=True, figsize=(12.5, 6.1),
                                         gridspec_kw={"height_ratios": [1, 1.6], "hspace": 0.06})
    robots_drawn = []
    for robot, (label, colour) in ROBOTS.items():
        for sign, marker in MARKERS.items():
            curve = sorted((float(r["margin"]), 100 * float(r["reachable_fraction"]),
                            100 * float(r["traditional_fraction"]))
                           for r in rows if r["robot"] == robot and r["sign"] == sign)
            # An assembly mode with no pose at all (the hexapod's +) would only be a line at 0.
            if not curve or all(reachable == 0 for _, reachable, _ in curve):
                continue
            if robot not in robots_drawn:
                robots_drawn.append(robot)
            style = dict(marker=marker, color=colour, markersize=6,
                         markerfacecolor="none" if sign == "-" else colour)
            for axis in (top, bottom):
                for column, line in ((1, "-"), (2, "--")):
                    # No line across the gap: nothing was measured between 0 and the smallest margin.
                    axis.plot([m for m, *_ in curve if m > 0], [p[column] for p in curve if p[0] > 0], line, **style)
                    axis.plot([exact_x for m, *_ in curve if m == 0], [p[column] for p in curve if p[0] == 0],
                              linestyle="none", **style)
    low = min(float(r[c]) for r in rows for c in ("reachable_fraction", "traditional_fraction")
              if float(r["reachable_fraction"]) > 0)
    top.set_ylim(BREAK, 100.3)
    bottom.set_ylim(min(100 * low, BREAK) - 2, BREAK)
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
    figure.supylabel("share of the workspace (%)")
    handles = [Line2D([], [], color=ROBOTS[r][1], linewidth=6, label=ROBOTS[r][0]) for r in robots_drawn]
    handles += [Line2D([], [], color="black", linestyle="-", label="reachable from start"),
                Line2D([], [], color="black", linestyle="--", label="traditional"),
                Line2D([], [], color="black", marker="^", linestyle="none", label="assembly mode +"),
                Line2D([], [], color="black", marker="v", markerfacecolor="none", linestyle="none",
                       label="assembly mode -")]
    # Beside the panels: inside, it would cover the points at the left edge.
    figure.subplots_adjust(right=0.74)
    figure.legend(handles=handles, loc="center right", fontsize=10)
    top.set_title(f"Effect of the dexterity margin, {step * 1000:g} mm grid "
                  f"(top: {BREAK:g} to 100 % magnified)", fontsize=13)
    figure.savefig(sys.argv[2], dpi=90)


if __name__ == "__main__":
    main()
