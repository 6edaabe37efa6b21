#!/usr/bin/env python3
"""Draws time and peak memory against 1/step from the CSV that bench_workspace --csv
writes (scripts/benchmark_scaling.sh), with the exponents of power laws fitted on steps
of 5 mm and less, and the memory estimate beside the measured peak. Prints the
exponents.

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
    quantities = (("process_s", "wall time of the analysis (s)"), ("peak_MiB", "peak memory (MiB)"))
    for axis, (column, label) in zip(axes, quantities):
        points = sorted((1000.0 / float(r["step_mm"]), float(r[column])) for r in rows)
        x = np.array([p[0] for p in points])
        y = np.array([p[1] for p in points])
        fit = x >= 1000.0 / FIT_MAX_STEP_MM
        slope, intercept = np.polyfit(np.log(x[fit]), np.log(y[fit]), 1)
        print(f"{column:9s} exponent {slope:.2f} (fitted on {fit.sum()} steps <= {FIT_MAX_STEP_MM:g} mm)")
        axis.loglog(x, y, "o", color="tab:blue", label=f"measured: ~ (1/step)^{slope:.2f}")
        line = np.linspace(x[fit].min(), x[fit].max(), 50)
        axis.loglog(line, np.exp(intercept) * line ** slope, "-", color="tab:blue", alpha=0.6)
        if column == "peak_MiB":
            estimates = sorted((1000.0 / float(r["step_mm"]), float(r["estimate_MiB"])) for r in rows)
            axis.loglog([p[0] for p in estimates], [p[1] for p in estimates], "x", color="tab:orange",
                        label="estimated before the run")
        axis.set_xlabel("1 / step (1/m)")
        axis.set_ylabel(label)
        axis.grid(True, which="both", alpha=0.3)
        axis.legend()
    # The targets of issue 15: 8 s and 1 GiB at 2 mm, 45 s and 3 GiB at 1 mm.
    for axis, targets in zip(axes, ((8.0, 45.0), (1024.0, 3072.0))):
        for target in targets:
            axis.axhline(target, color="grey", linestyle=":", linewidth=1)
    figure.suptitle("delta-like robot, both assembly modes with regions and transitions, 2 cores")
    figure.tight_layout()
    figure.savefig(sys.argv[2], dpi=90)


if __name__ == "__main__":
    main()
