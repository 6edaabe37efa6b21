#!/usr/bin/env python3
"""Draws a design study's results (the CSV of `mow sweep`, docs/sweep.md) as a PNG: one
figure against one parameter (a line; when the study varies other parameters too, one
line per combination of their values), or over two parameters as a heat map. Designs that
are not ok (invalid_robot, no_workspace, over_budget, failed) have no value: crosses on
the x axis of a line, crossed grey cells of a heat map. The best design (the largest
value; for seconds the fewest) is starred on a line, outlined on a heat map, and printed.

usage: plot_sweep.py CSV --x PARAM [--y PARAM] [--figure NAME] --out PNG [--dpi N]

PARAM names a parameter column as the CSV's header does (its `name`, its field path,
scale(path) or offset(path)); for scale and offset the path alone will do. The picture is
8 x 6 inches at --dpi (default 100: 800 x 600 pixels). Needs Debian's python3-matplotlib
(apt-get install -y --no-install-recommends python3-matplotlib); run it with /usr/bin/python3."""
import argparse
import csv
import math
import sys
from pathlib import Path

try:
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    import numpy as np
    from matplotlib.lines import Line2D
    from matplotlib.patches import Patch, Rectangle
except ImportError as error:
    sys.exit(f"plot_sweep.py: {error}; install Debian's python3-matplotlib and run with /usr/bin/python3")

FIGURE_SIZE = (8, 6)  # inches
STATUS_COLOURS = {"invalid_robot": "#d62728", "no_workspace": "#ff7f0e", "over_budget": "#9467bd", "failed": "#000000"}
FAILED_CELL = "#d9d9d9"
ANNOTATED_CELLS = 12  # heat maps up to this many cells a side get each cell's value written in it
plt.rcParams.update({"font.size": 11, "axes.titlesize": 12, "figure.titlesize": 13})


def fail(message):
    sys.exit(f"plot_sweep.py: {message}")


class Results:
    """A results file: its study, parameter and figure columns, and its rows as
    (design, parameter values, status, {figure: value or NaN})."""

    def __init__(self, path):
        self.path = path
        try:
            text = Path(path).read_text()
        except (OSError, UnicodeDecodeError) as error:
            fail(f"{path}: cannot read it ({getattr(error, 'strerror', None) or error})")
        lines = text.splitlines()
        if not lines or not lines[0].startswith("# study: "):
            fail(f"{path}: not a results file of mow sweep (its first line is not '# study: ...')")
        # A study still running, or killed mid-row, may end in a row without its line end.
        if not text.endswith("\n"):
            lines.pop()
        self.study = lines[0][len("# study: "):]
        reader = csv.reader(lines[1:])
        header = next(reader, [])
        if len(header) < 3 or header[0] != "design" or header[-1] != "reason" or "status" not in header:
            fail(f"{path}:2: not the column line of mow sweep's results (design,...,status,...,reason)")
        status_at = header.index("status")
        # Since issue 28 a row's check (16 hex digits over its cells) comes before the reason.
        figures_end = -2 if header[-2] == "check" else -1
        self.parameters, self.figures = header[1:status_at], header[status_at + 1:figures_end]
        self.rows = []
        for number, cells in enumerate(reader, start=3):
            if len(cells) != len(header):
                fail(f"{path}:{number}: {len(cells)} cells where the header has {len(header)}")
            try:
                values = [float(cell) for cell in cells[1:status_at]]
                figures = {name: float(cell) if cell else math.nan
                           for name, cell in zip(self.figures, cells[status_at + 1:figures_end])}
                self.rows.append((int(cells[0]), values, cells[status_at], figures))
            except ValueError as error:
                fail(f"{path}:{number}: {error}")

    def parameter(self, name, option):
        """The index of the parameter column `name` names."""
        for index, column in enumerate(self.parameters):
            if column in (name, f"scale({name})", f"offset({name})"):
                return index
        fail(f"{option} {name!r}: no such parameter in {self.path}; its parameters: {', '.join(self.parameters)}")

    def figure(self, name):
        if name not in self.figures:
            fail(f"--figure {name!r}: not a column of {self.path}; its figures: {', '.join(self.figures)}")
        return name


def figure_label(figure):
    if figure.endswith("_volume") or "_volume_" in figure:
        return f"{figure} (m³; m² for a planar robot)"
    return f"{figure} (s)" if figure == "seconds" else figure


def best_row(rows, figure):
    """The best ok row: the largest value, for seconds the fewest; the first design of a tie."""
    ok = [r for r in rows if r[2] == "ok" and not math.isnan(r[3][figure])]
    if not ok:
        return None
    sign = -1 if figure == "seconds" else 1
    return max(ok, key=lambda r: (sign * r[3][figure], -r[0]))


def failure_handles(rows):
    """Legend entries of the designs without a value, a cross per status with its count."""
    counts = {}
    for row in rows:
        if row[2] != "ok":
            counts[row[2]] = counts.get(row[2], 0) + 1
    return [Line2D([], [], marker="x", color=STATUS_COLOURS.get(status, "black"), linestyle="none", markersize=9,
                   mew=2, label=f"{status} ({count})") for status, count in sorted(counts.items())]


def star(axis, x, y, face):
    axis.plot(x, y, marker="*", color=face, markersize=16, markeredgecolor="black", linestyle="none", zorder=5)


def line_figure(results, x, figure, axis, best):
    """The figure against parameter x: a line per combination of the other parameters that
    vary. Returns how the best design is marked."""
    others = [p for p in range(len(results.parameters))
              if p != x and len({r[1][p] for r in results.rows}) > 1]
    groups = {}
    for row in results.rows:
        if row[2] == "ok":
            groups.setdefault(tuple(row[1][p] for p in others), []).append((row[1][x], row[3][figure]))
    colours = plt.cm.viridis(np.linspace(0, 0.9, max(len(groups), 1)))
    for colour, (key, points) in zip(colours, sorted(groups.items())):
        points.sort()
        label = ", ".join(f"{results.parameters[p]} = {v:g}" for p, v in zip(others, key)) or None
        axis.plot([p[0] for p in points], [p[1] for p in points], "o-", color=colour, markersize=4, label=label)
    for row in results.rows:
        if row[2] != "ok":
            # On the x axis itself, whatever the figure's range.
            axis.plot(row[1][x], 0, "x", color=STATUS_COLOURS.get(row[2], "black"), markersize=9, mew=2,
                      transform=axis.get_xaxis_transform(), clip_on=False)
    if best:
        star(axis, best[1][x], best[3][figure], "black")
    axis.set_xlabel(results.parameters[x])
    axis.set_ylabel(figure_label(figure))
    axis.grid(True, alpha=0.3)
    handles = axis.get_legend_handles_labels()[0] + failure_handles(results.rows)
    if handles and len(handles) <= 12:
        axis.legend(handles=handles, fontsize=9)
    return "★ the best"


def cell_edges(values):
    """Cell borders midway between neighbouring values, and as far out at the ends."""
    values = np.asarray(values)
    if len(values) == 1:
        return np.array([values[0] - 0.5, values[0] + 0.5])
    middles = (values[:-1] + values[1:]) / 2
    return np.concatenate([[2 * values[0] - middles[0]], middles, [2 * values[-1] - middles[-1]]])


def heat_map(results, x, y, figure, axis, canvas, best):
    """The figure over parameters x and y, a cell per design; a sampled study (no grid) as
    coloured points. Returns how the best design is marked."""
    xs = sorted({r[1][x] for r in results.rows})
    ys = sorted({r[1][y] for r in results.rows})
    cells = {}
    for row in results.rows:
        key = (row[1][x], row[1][y])
        if key in cells:
            others = [p for i, p in enumerate(results.parameters) if i not in (x, y)]
            fail(f"designs {cells[key][0]} and {row[0]} share the cell {results.parameters[x]} = {key[0]:g}, "
                 f"{results.parameters[y]} = {key[1]:g}: the study varies {', '.join(others)} as well; "
                 "plot one parameter against another with --x alone")
        cells[key] = row
    ok = [r for r in results.rows if r[2] == "ok" and not math.isnan(r[3][figure])]
    values = [r[3][figure] for r in ok]
    limits = (min(values), max(values)) if values else (0, 1)
    failed = [r for r in results.rows if r[2] != "ok"]
    gridded = len(cells) * 2 >= len(xs) * len(ys)  # a sampled study's designs fill few cells of their grid
    if gridded:
        x_edges, y_edges = cell_edges(xs), cell_edges(ys)
        image = np.full((len(ys), len(xs)), np.nan)
        for row in ok:
            image[ys.index(row[1][y]), xs.index(row[1][x])] = row[3][figure]
        mesh = axis.pcolormesh(x_edges, y_edges, np.ma.masked_invalid(image), cmap="viridis", vmin=limits[0],
                               vmax=limits[1], shading="flat")
        if len(xs) <= ANNOTATED_CELLS and len(ys) <= ANNOTATED_CELLS:
            for row in ok:
                value = row[3][figure]
                light = (value - limits[0]) / ((limits[1] - limits[0]) or 1) > 0.6
                axis.text(row[1][x], row[1][y], f"{value:.3g}", ha="center", va="center", fontsize=8,
                          color="black" if light else "white")
        for row in failed:
            i, j = xs.index(row[1][x]), ys.index(row[1][y])
            axis.fill_between(x_edges[i:i + 2], y_edges[j], y_edges[j + 1], color=FAILED_CELL, linewidth=0)
        if best:
            # An outline, not a marker: the cell's value stays readable.
            i, j = xs.index(best[1][x]), ys.index(best[1][y])
            axis.add_patch(Rectangle((x_edges[i], y_edges[j]), x_edges[i + 1] - x_edges[i],
                                     y_edges[j + 1] - y_edges[j], fill=False, edgecolor="#e31a1c", linewidth=3,
                                     zorder=4))
        axis.set_xlim(x_edges[0], x_edges[-1])
        axis.set_ylim(y_edges[0], y_edges[-1])
    else:
        mesh = axis.scatter([r[1][x] for r in ok], [r[1][y] for r in ok], c=values, cmap="viridis",
                            vmin=limits[0], vmax=limits[1], s=60)
        if best:
            star(axis, best[1][x], best[1][y], "white")
    for row in failed:
        axis.plot(row[1][x], row[1][y], "x", color=STATUS_COLOURS.get(row[2], "black"), markersize=10, mew=2)
    canvas.colorbar(mesh, ax=axis, label=figure_label(figure))
    axis.set_xlabel(results.parameters[x])
    axis.set_ylabel(results.parameters[y])
    if failed:
        handles = ([Patch(color=FAILED_CELL, label="no value:")] if gridded else []) + failure_handles(failed)
        axis.legend(handles=handles, fontsize=9, loc="upper left", bbox_to_anchor=(0, -0.1), ncol=len(handles),
                    frameon=False)
    return "outlined in red: the best" if gridded else "★ the best"


def parse_arguments():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0],
                                     formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("csv", help="the results file of mow sweep")
    parser.add_argument("--x", required=True, help="the parameter along x")
    parser.add_argument("--y", help="a second parameter, along y: a heat map")
    parser.add_argument("--figure", default="maximal_volume_positive", help="the figure column drawn")
    parser.add_argument("--out", required=True, help="the PNG written")
    parser.add_argument("--dpi", type=int, default=100)
    arguments = parser.parse_args()
    if arguments.dpi <= 0:
        parser.error("--dpi must be > 0")
    return arguments


def main():
    arguments = parse_arguments()
    results = Results(arguments.csv)
    x = results.parameter(arguments.x, "--x")
    y = results.parameter(arguments.y, "--y") if arguments.y else None
    if y == x:
        fail(f"--x and --y name the same parameter, {results.parameters[x]}")
    figure = results.figure(arguments.figure)
    if not results.rows:
        fail(f"{arguments.csv}: no designs recorded yet")

    canvas, axis = plt.subplots(figsize=FIGURE_SIZE)
    canvas.subplots_adjust(left=0.12, right=0.97 if y is None else 0.99, top=0.88, bottom=0.1 if y is None else 0.16)
    best = best_row(results.rows, figure)
    if y is None:
        marked = line_figure(results, x, figure, axis, best)
    else:
        marked = heat_map(results, x, y, figure, axis, canvas, best)
    ok = sum(1 for r in results.rows if r[2] == "ok")
    # The parameters are the axes' labels: a title naming them too would not fit.
    canvas.suptitle(f"{Path(arguments.csv).name}: {figure}", y=0.975)
    canvas.text(0.5, 0.915, f"study {results.study}: {len(results.rows)} designs, {ok} ok" +
                (f"; {marked}" if best else ""), ha="center", fontsize=10, color="dimgrey")
    Path(arguments.out).parent.mkdir(parents=True, exist_ok=True)
    canvas.savefig(arguments.out, dpi=arguments.dpi)
    plt.close(canvas)
    summary = f"wrote {arguments.out}: {figure} of {ok} ok designs out of {len(results.rows)}"
    if best:
        where = ", ".join(f"{name} = {value:g}" for name, value in zip(results.parameters, best[1]))
        word = "the fewest" if figure == "seconds" else "the largest"
        summary += f"; {word} {best[3][figure]:.6g} at design {best[0]} ({where})"
    print(summary)


if __name__ == "__main__":
    main()
