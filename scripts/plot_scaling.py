#!/usr/bin/env python3
"""Draws time and peak memory against 1/step, dense and adaptive, from the CSV that
bench_workspace --csv writes (scripts/benchmark_scaling.sh), with the exponents of
power laws fitted on steps of 5 mm and less. Prints the exponents.

usage: plot_scaling.py SCALING.csv OUT.png
Needs Debian's python3-matplotlib (apt-get install -y --no-install-recommends
python3-matplotlib); run it with /usr/bin/python3."""
import csv
import sys

try:
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    import numpy as np
except ImportError as error:
    sys.exit(f"plot_scaling.py: {error}; install Debian's python3-matplotlib and run with /usr/bin/python3")

FIT_MAX_STEP_MM = 5.0


def main():
    if len(sys.argv) != 3:
        sys.exit(__doc__)
    with open(sys.argv[1], newline="") as source:
        rows = list(csv.DictReader(source))
    if not rows:
        sys.exit(f"plot_scaling.py: no rows in {sys.argv[1]}")
    figure, axes = plt.subplots(1, 2, figsize=(11, 4.5))
    quantities = (("total_s", "analysis wall time (s)"), ("peak_MiB", "peak memory (MiB)"))
    for axis, (column, label) in zip(axes, quantities):
        for method, colour in (("dense", "tab:red"), ("adaptive", "tab:blue")):
            points = sorted((1000.0 / float(r["step_mm"]), float(r[column])) for r in rows if r["method"] == method)
            if not points:
                continue
            x = np.array([p[0] for p in points])
            y = np.array([p[1] for p in points])
            fit = x >= 1000.0 / FIT_MAX_STEP_MM
            slope, intercept = np.polyfit(np.log(x[fit]), np.log(y[fit]), 1)
            print(f"{method:8s} {column:9s} exponent {slope:.2f} (fitted on {fit.sum()} steps <= {FIT_MAX_STEP_MM:g} mm)")
            axis.loglog(x, y, "o", color=colour, label=f"{method}: ~ (1/step)^{slope:.2f}")
            line = np.linspace(x[fit].min(), x[fit].max(), 50)
            axis.loglog(line, np.exp(intercept) * line ** slope, "-", color=colour, alpha=0.6)
        axis.set_xlabel("1 / step (1/m)")
        axis.set_ylabel(label)
        axis.grid(True, which="both", alpha=0.3)
        axis.legend()
    axes[0].axhline(30.0, color="grey", linestyle=":", linewidth=1)
    axes[1].axhline(2048.0, color="grey", linestyle=":", linewidth=1)
    figure.suptitle("delta-like robot, both assembly modes with regions and transitions, 2 cores")
    figure.tight_layout()
    figure.savefig(sys.argv[2], dpi=90)


if __name__ == "__main__":
    main()
