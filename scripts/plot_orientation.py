#!/usr/bin/env python3
"""Draws what scripts/orientation_results.sh measures: left, per robot, the total-orientation
volume of the maximal workspace reachable from the start (solid) and of the traditional one
(dashed) against the tilt-and-torsion envelope; right, the long-crank hexapod's coverage at
20 deg in the plane of positions where they differ most, maximal against traditional.

usage: plot_orientation.py ENVELOPES.csv SLICE.csv OUT.png
Needs Debian's python3-matplotlib; run it with /usr/bin/python3."""
import csv
import sys

try:
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
except ImportError as error:
    sys.exit(f"plot_orientation.py: {error}; install Debian's python3-matplotlib and run with /usr/bin/python3")

ROBOTS = {("hexapod", -1): ("long-crank hexapod, AM -", "tab:blue"), ("hexaglide", 1): ("hexaglide, AM +", "tab:orange")}


def main():
    if len(sys.argv) != 4:
        sys.exit(__doc__)
    envelopes, slice_path, out = sys.argv[1:]
    with open(envelopes) as f:
        rows = list(csv.DictReader(f))
    with open(slice_path) as f:
        cells = list(csv.DictReader(f))
    figure, (volumes, maximal, traditional) = plt.subplots(1, 3, figsize=(15, 4.6),
                                                          gridspec_kw={"width_ratios": [1.25, 1, 1]})
    for (robot, sign), (label, colour) in ROBOTS.items():
        picked = [r for r in rows if r["robot"] == robot and int(r["sign"]) == sign]
        degrees = [float(r["envelope_deg"]) for r in picked]
        volumes.plot(degrees, [1e3 * float(r["total_orientation_maximal"]) for r in picked], "-o", color=colour,
                     label=label + ": maximal")
        volumes.plot(degrees, [1e3 * float(r["total_orientation_traditional"]) for r in picked], "--s", color=colour,
                     label=label + ": traditional")
    volumes.set_xlabel("tilt and torsion envelope (deg)")
    volumes.set_ylabel("total-orientation volume (litres)")
    volumes.set_title("positions reaching every orientation of the envelope")
    volumes.grid(True, alpha=0.3)
    volumes.legend(fontsize=8)
    xs = [float(c["x"]) for c in cells]
    ys = [float(c["y"]) for c in cells]
    for axes, column, title in ((maximal, "maximal_negative", "maximal, reachable from the start"),
                                (traditional, "traditional_negative", "traditional (the start's region)")):
        shares = [float(c[column]) for c in cells]
        image = axes.scatter(xs, ys, c=shares, cmap="jet", vmin=0.0, vmax=1.0, marker="s", s=55)
        axes.set_aspect("equal")
        axes.set_xlabel("x (m)")
        axes.set_title(title, fontsize=10)
    maximal.set_ylabel("y (m)")
    figure.colorbar(image, ax=[maximal, traditional], label="share of the orientations reached")
    maximal.annotate(f"long-crank hexapod, 20 deg envelope, positions at z = {float(cells[0]['z']):.2f} m",
                     xy=(0.0, 1.12), xycoords="axes fraction", fontsize=10)
    figure.savefig(out, dpi=110, bbox_inches="tight")


if __name__ == "__main__":
    main()
