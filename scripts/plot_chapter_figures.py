#!/usr/bin/env python3
"""The chapter's figures as pictures (Macho, Altuzarra and Hernandez, "Maximal Operational
Workspace of Parallel Manipulators"; ../shared/docs/method.md), drawn from what mow computes:

  chapter_singularities_<plane>.png  per working mode, on a plane: the sign of det J_DKP, the
                                     DKP singularity curves and the IKP boundary, coloured by
                                     the input whose chains reach their extreme position there
  chapter_regions_<plane>.png        per working mode, its singularity-free regions (3-D
                                     components) where they cut the plane
  chapter_maximal_<plane>.png        per assembly mode, the maximal operational workspace on the
                                     plane (how many working modes' regions cover each cell), the
                                     traditional workspace and the transition points (Fig. 13)
  chapter_path.png                   the demo's path (config/demo/<robot>.yaml, the Fig. 14-like
                                     one), coloured by working mode, its transitions labelled

Nothing kinematic is computed here: `mow workspace --out` gives the analysis (through mow's
cache), `mow eval` a lattice of poses on each plane, `mow plan --out` the path. The regions
are read from the analysis's regions_<mode>.ot octrees (docs/mow.md, `mow workspace`: leaves
carry region ids of summary.json's table; grid cells are OctoMap cells of the step).

usage: plot_chapter_figures.py [--robot FILE] [--step S] [--resolution R] [--plane z=0.4 ...]
                               [--demo FILE] [--out-dir DIR] [--cache DIR] [--mow BINARY]
Needs Debian's python3-matplotlib, python3-numpy and python3-yaml; run it with /usr/bin/python3."""
import argparse
import csv
import json
import math
import os
import re
import shutil
import struct
import subprocess
import sys
import tempfile
import textwrap
import time
from pathlib import Path

try:
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    import numpy as np
    import yaml
    from matplotlib.colors import ListedColormap, to_rgb, to_rgba
    from matplotlib.lines import Line2D
    from matplotlib.patches import Patch
    from matplotlib.patheffects import withStroke
except ImportError as error:
    sys.exit(f"plot_chapter_figures.py: {error}; install Debian's python3-matplotlib and python3-yaml "
             "and run with /usr/bin/python3")

REPO = Path(__file__).resolve().parent.parent
AXES = "xyz"
# A plane normal to an axis is drawn over the other two, in this order.
PLANE_AXES = {0: (1, 2), 1: (0, 2), 2: (0, 1)}
KEY_OFFSET = 1 << 15  # OctoMap key of lattice cell 0 (cell k spans [k, k + 1) steps)
SIGN_FILL = {1: "#f6bd82", -1: "#9dc3e6"}
INPUT_COLOURS = ["#d62728", "#2ca02c", "#7b3fb5", "#8c564b", "#e377c2", "#17becf"]
# Working modes in mow's order (ppp ppn pnp pnn npp npn nnp nnn for three inputs); none is an
# input's colour, so a path's colour never reads as an IKP boundary.
MODE_COLOURS = ["#393b79", "#bcbd22", "#17becf", "#ff7f0e", "#8c564b", "#1f77b4", "#7f7f7f", "#e377c2"]
# Region colours: a family per sign, darkest for the largest region of a working mode.
REGION_COLOURS = {1: ["#c2410c", "#f59e0b", "#fb7185", "#a16207", "#fdba74"],
                  -1: ["#1d4ed8", "#0d9488", "#7c3aed", "#38bdf8", "#64748b"]}
DEBRIS_COLOUR = "#404040"
OUTSIDE_MAXIMAL = "#cfcfcf"
SLAB = 0.02  # m: how near a transition's plane the path is drawn solid
plt.rcParams.update({"font.size": 11, "axes.titlesize": 12, "figure.titlesize": 15, "hatch.color": "#505050",
                     "hatch.linewidth": 0.6})


def fail(message):
    sys.exit(f"plot_chapter_figures.py: {message}")


def parse_arguments():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0],
                                     formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--robot", default=str(REPO / "config" / "delta_like.yaml"), help="robot file")
    parser.add_argument("--step", type=float, default=0.01, help="grid step of the analysis (m)")
    parser.add_argument("--resolution", type=float, default=0.004,
                        help="spacing (m) of the poses mow eval classifies on each plane")
    parser.add_argument("--plane", action="append", metavar="AXIS=VALUE",
                        help="a plane normal to x, y or z (m), drawn through the centre of the grid cell that holds "
                             "it; repeat for more (default: the middle of the analysis's box along z, then along x)")
    parser.add_argument("--demo", help="start and goal of the path (default: config/demo/<robot file name>, "
                                       "no path figure when there is none)")
    parser.add_argument("--out-dir", default=str(REPO / "docs" / "images"), help="where the PNGs go")
    parser.add_argument("--cache", help="mow's cache folder (default: mow's own)")
    parser.add_argument("--mow", help="the mow binary (default: the catkin workspace's, else mow on PATH)")
    parser.add_argument("--dpi", type=int, default=90)
    arguments = parser.parse_args()
    planes = []
    for text in arguments.plane or []:
        axis, _, value = text.partition("=")
        try:
            planes.append(({"x": 0, "y": 1, "z": 2}[axis.strip()], float(value)))
        except (KeyError, ValueError):
            parser.error(f"--plane {text}: expected x=VALUE, y=VALUE or z=VALUE (m)")
    arguments.planes = planes
    if not (arguments.step > 0 and arguments.resolution > 0):
        parser.error("--step and --resolution must be > 0")
    return arguments


def find_mow(given):
    if given:
        return given
    workspace = Path(os.environ.get("MOW_WS", REPO / ".catkin_ws"))
    built = workspace / "devel" / "lib" / "maximal_workspace" / "mow"
    if built.is_file():
        return str(built)
    on_path = shutil.which("mow")
    if not on_path:
        fail(f"no mow binary at {built} nor on PATH; build the package (README) or give --mow")
    return on_path


class Mow:
    """Runs mow; a failure ends the script with mow's own message."""

    def __init__(self, binary, robot, step, cache):
        self.binary, self.robot = binary, robot
        self.analysis_options = ["--step", repr(step)] + (["--cache", cache] if cache else [])

    def run(self, command, *options, allowed=(0,)):
        arguments = [self.binary, command, "--robot", self.robot, *options]
        done = subprocess.run(arguments, capture_output=True, text=True)
        if done.returncode not in allowed:
            reason = done.stderr.strip() or done.stdout.strip()
            fail(f"{' '.join(arguments)} failed (exit {done.returncode}):\n{reason}")
        return done


def read_region_octree(path):
    """The occupied leaves of a RegionLabelOcTree file as an array of rows (kx, ky, kz, side,
    label): the lattice cell of the leaf's lowest corner and its side, in cells."""
    data = path.read_bytes()
    end_of_header = data.find(b"\ndata\n")
    if not data.startswith(b"# Octomap OcTree file") or end_of_header < 0:
        fail(f"{path}: not an OctoMap .ot file")
    fields = dict(line.partition(" ")[::2] for line in data[:end_of_header].decode().splitlines()[1:]
                  if line and not line.startswith("#"))
    if fields.get("id") != "RegionLabelOcTree":
        fail(f"{path}: a {fields.get('id')}, not a RegionLabelOcTree")
    leaves = []
    offset = end_of_header + len(b"\ndata\n")
    # OctoMap's layout: each node's data (float log-odds, then the int32 label, native byte
    # order), a byte of which children exist (bit i: child i, whose key has bit 0 of i in x,
    # bit 1 in y, bit 2 in z), then those children, depth first. The root spans every key.
    node = struct.Struct("=fiB")
    stack = [(0, 0, 0, 1 << 16)] if int(fields["size"]) > 0 else []
    while stack:
        x, y, z, side = stack.pop()
        _, label, children = node.unpack_from(data, offset)
        offset += node.size
        if not children:
            leaves.append((x - KEY_OFFSET, y - KEY_OFFSET, z - KEY_OFFSET, side, label))
            continue
        half = side >> 1
        for i in range(7, -1, -1):  # child 0 is read next
            if children >> i & 1:
                stack.append((x + (i & 1) * half, y + (i >> 1 & 1) * half, z + (i >> 2 & 1) * half, half))
    if offset != len(data):
        fail(f"{path}: {len(data) - offset} bytes left after the tree; not the layout this script reads")
    table = np.array(leaves, dtype=np.int64).reshape(-1, 5)
    return table[table[:, 4] >= 0]


class Plane:
    """A plane normal to one axis through a cell centre of the analysis, with its image of
    grid cells (axes u, v) and its lattice of poses for mow eval."""

    def __init__(self, axis, value, grid, resolution):
        self.axis = axis
        self.u, self.v = PLANE_AXES[axis]
        step = grid["step"]
        self.k = math.floor(value / step)
        self.value = (self.k + 0.5) * step
        lo, hi = grid["bounds"][axis]
        if not lo <= self.value <= hi:
            fail(f"plane {AXES[axis]} = {value:g} m is outside the analysis's box [{lo:.3f}, {hi:.3f}] m")
        # Grid cells whose centres lie in the box (as mow's grid takes them).
        self.cells = [(math.ceil(grid["bounds"][d][0] / step - 0.5), math.floor(grid["bounds"][d][1] / step - 0.5))
                      for d in (self.u, self.v)]
        self.cell_extent = [self.cells[0][0] * step, (self.cells[0][1] + 1) * step,
                            self.cells[1][0] * step, (self.cells[1][1] + 1) * step]
        self.us = np.arange(grid["bounds"][self.u][0] + resolution / 2, grid["bounds"][self.u][1], resolution)
        self.vs = np.arange(grid["bounds"][self.v][0] + resolution / 2, grid["bounds"][self.v][1], resolution)
        self.labels = {}  # working mode -> image of region ids (-1: none), rows along v

    @property
    def name(self):
        return f"{AXES[self.axis]}_{self.value:.3f}m"

    @property
    def title(self):
        return f"{AXES[self.axis]} = {self.value:.3f} m"

    def poses(self):
        grid_u, grid_v = np.meshgrid(self.us, self.vs)
        poses = np.empty((grid_u.size, 3))
        poses[:, self.u], poses[:, self.v], poses[:, self.axis] = grid_u.ravel(), grid_v.ravel(), self.value
        return poses

    def fill(self, mode, leaves):
        """Paints the leaves that cut the plane into the mode's label image."""
        image = np.full((self.cells[1][1] - self.cells[1][0] + 1, self.cells[0][1] - self.cells[0][0] + 1), -1,
                        dtype=np.int64)
        cut = leaves[(leaves[:, self.axis] <= self.k) & (self.k < leaves[:, self.axis] + leaves[:, 3])]
        for leaf in cut:
            u0, v0 = leaf[self.u] - self.cells[0][0], leaf[self.v] - self.cells[1][0]
            image[max(v0, 0):max(v0 + leaf[3], 0), max(u0, 0):max(u0 + leaf[3], 0)] = leaf[4]
        self.labels[mode] = image


class Analysis:
    """What `mow workspace --out` wrote: summary.json's tables, transitions.csv, and the
    region octrees read into the planes asked for."""

    def __init__(self, folder):
        self.folder = folder
        summary = json.loads((folder / "summary.json").read_text())
        grid = summary["grid"]
        if grid["variables"] != ["x", "y", "z"] or len(set(grid["steps"])) != 1:
            fail("the figures need an analysis over x y z with one step")
        self.grid = {"step": grid["steps"][0], "bounds": grid["bounds"]}
        self.summary = summary
        self.modes = summary["working_modes"]
        self.start_mode = summary["start_mode"]
        self.regions = {r["id"]: r for r in summary["regions"]}
        self.assembly = {a["sign"]: a for a in summary["assembly_modes"]}

    def read_regions(self, planes, projection_sign=None):
        """Fills every plane's label images, and returns the projections along x, y and z
        of the maximal operational workspace of assembly mode projection_sign (cells of a
        non-debris region of that sign in some working mode)."""
        step = self.grid["step"]
        ranges = [(math.ceil(lo / step - 0.5), math.floor(hi / step - 0.5)) for lo, hi in self.grid["bounds"]]
        projections = {}
        for axis in range(3):
            u, v = PLANE_AXES[axis]
            projections[axis] = np.zeros((ranges[v][1] - ranges[v][0] + 1, ranges[u][1] - ranges[u][0] + 1), bool)
        for mode in self.modes:
            leaves = read_region_octree(self.folder / f"regions_{mode}.ot")
            for plane in planes:
                plane.fill(mode, leaves)
            if projection_sign is None:
                continue
            keep = np.array([not self.regions[label]["debris"] and self.regions[label]["sign"] == projection_sign
                             for label in leaves[:, 4]], dtype=bool)
            for leaf in leaves[keep]:
                for axis, image in projections.items():
                    u, v = PLANE_AXES[axis]
                    image[leaf[v] - ranges[v][0]:leaf[v] - ranges[v][0] + leaf[3],
                          leaf[u] - ranges[u][0]:leaf[u] - ranges[u][0] + leaf[3]] = True
        extents = {axis: [ranges[u][0] * step, (ranges[u][1] + 1) * step,
                          ranges[v][0] * step, (ranges[v][1] + 1) * step] for axis, (u, v) in PLANE_AXES.items()}
        return projections, extents

    def transition_points(self):
        """transitions.csv as (positions n x 3, input index per point, indices of the
        transitions each point serves)."""
        with open(self.folder / "transitions.csv", newline="") as source:
            rows = list(csv.DictReader(source))
        positions = np.array([[float(r["x"]), float(r["y"]), float(r["z"])] for r in rows]).reshape(-1, 3)
        inputs = np.array([int(r["input"]) for r in rows], dtype=int)
        served = [[int(t) for t in r["transitions"].split(";")] for r in rows]
        return positions, inputs, served


def evaluate(mow, plane, folder):
    """mow eval on the plane's lattice: per column name, an image (rows along v)."""
    poses_file, table_file = folder / f"poses_{plane.name}.csv", folder / f"eval_{plane.name}.csv"
    np.savetxt(poses_file, plane.poses(), delimiter=",", header="x,y,z", comments="", fmt="%.10g")
    mow.run("eval", "--poses", str(poses_file), "--out", str(table_file))
    with open(table_file) as source:
        header = source.readline().strip().split(",")
    wanted = [i for i, name in enumerate(header) if name == "inside" or name.split("_")[0] in
              ("disc", "measure", "admissible")]
    table = np.loadtxt(table_file, delimiter=",", skiprows=1, usecols=wanted, ndmin=2)
    shape = (len(plane.vs), len(plane.us))
    return {header[i]: table[:, j].reshape(shape) for j, i in enumerate(wanted)}


def robot_inputs(robot_file):
    """Input names in the robot file's order (the letters of a working mode's name follow
    it), per input its chains, and per input its unit (rad for a crank, m for a slider)."""
    robot = yaml.safe_load(Path(robot_file).read_text())
    inputs = [i["name"] for i in robot["inputs"]]
    couples = {name: [c["name"] for c in robot["chains"] if c["input"] == name] for name in inputs}
    units = {c["input"]: "rad" if c["type"] == "RSS" else "m" for c in robot["chains"]}
    return inputs, couples, units


class Layout:
    """Panels of a fixed size in inches under a title and a note, above a legend: the
    margins stay the same whatever the number of panels."""
    TOP = 1.45  # title, a note of up to two lines and the panels' own titles
    LEFT, RIGHT, GAP_W, GAP_H = 0.75, 0.25, 0.3, 0.85

    def __init__(self, count, panel, legend_rows, right=RIGHT, columns=4, gaps=(GAP_W, GAP_H)):
        self.count = count
        self.columns = min(columns, count)
        self.rows = math.ceil(count / self.columns)
        width, height = panel
        bottom = 0.75 + 0.3 * legend_rows
        self.size = (self.LEFT + self.columns * width + (self.columns - 1) * gaps[0] + right,
                     self.TOP + self.rows * height + (self.rows - 1) * gaps[1] + bottom)
        self.adjust = dict(left=self.LEFT / self.size[0], right=1 - right / self.size[0],
                           top=1 - self.TOP / self.size[1], bottom=bottom / self.size[1],
                           wspace=gaps[0] / width, hspace=gaps[1] / height)

    def panels(self):
        figure, axes = plt.subplots(self.rows, self.columns, figsize=self.size, squeeze=False, sharex=True,
                                    sharey=True)
        figure.subplots_adjust(**self.adjust)
        for axis in axes.flat[self.count:]:
            axis.set_visible(False)
        return figure, list(axes.flat[:self.count])

    def frame(self, figure, title, note, handles, legend_columns):
        height = self.size[1]
        figure.suptitle(title, y=1 - 0.15 / height, va="top")
        # About 13 characters an inch at this size.
        figure.text(0.5, 1 - 0.55 / height, textwrap.fill(note, int(13 * self.size[0])), ha="center", va="top",
                    fontsize=10, color="dimgrey")
        figure.legend(handles=handles, loc="lower center", ncol=legend_columns, frameon=False,
                      bbox_to_anchor=(0.5, 0.05 / height))


def panel_size(extent, widest=3.9, tallest=4.6):
    """Inches of one panel showing extent with metres equal on both axes."""
    ratio = (extent[3] - extent[2]) / (extent[1] - extent[0])
    width = min(widest, tallest / ratio)
    return width, width * ratio


def workspace_extent(plane, inside, pad=0.03):
    """The part of the plane the workspace occupies, padded."""
    rows, columns = np.nonzero(inside > 0.5)
    if rows.size == 0:
        fail(f"the plane {plane.title} misses the workspace; choose another")
    return [plane.us[columns.min()] - pad, plane.us[columns.max()] + pad,
            plane.vs[rows.min()] - pad, plane.vs[rows.max()] + pad]


def label_axes(axis, plane, extent, left, bottom):
    axis.set_xlim(extent[0], extent[1])
    axis.set_ylim(extent[2], extent[3])
    axis.set_aspect("equal")
    if bottom:
        axis.set_xlabel(f"{AXES[plane.u]} (m)")
    if left:
        axis.set_ylabel(f"{AXES[plane.v]} (m)")


def mode_title(analysis, mode):
    return f"WM {mode}" + (" (start)" if mode == analysis.start_mode else "")


def lattice_extent(plane, resolution):
    return [plane.us[0] - resolution / 2, plane.us[-1] + resolution / 2,
            plane.vs[0] - resolution / 2, plane.vs[-1] + resolution / 2]


def cell_centres(plane, shape, step):
    return (plane.cell_extent[0] + (np.arange(shape[1]) + 0.5) * step,
            plane.cell_extent[2] + (np.arange(shape[0]) + 0.5) * step)


def draw_ikp_boundary(axis, plane, table, inputs, couples, linewidth=2.2):
    """Where the workspace ends, coloured by the input whose chains cannot be assembled
    beyond: per input the zero level of its chains' smallest discriminant, kept where the
    other inputs' chains are assembled."""
    reach = {name: np.min([table[f"disc_{c}"] for c in couples[name]], axis=0) for name in inputs}
    for i, name in enumerate(inputs):
        others = [reach[o] for o in inputs if o != name]
        field = np.where(np.min(others, axis=0) >= 0, reach[name], np.nan) if others else reach[name]
        if np.nanmin(field, initial=0) < 0 < np.nanmax(field, initial=0):
            axis.contour(plane.us, plane.vs, field, levels=[0], colors=INPUT_COLOURS[i % len(INPUT_COLOURS)],
                         linewidths=linewidth)


def ikp_handles(inputs):
    return [Line2D([], [], color=INPUT_COLOURS[i % len(INPUT_COLOURS)], linewidth=2.5,
                   label=f"IKP singularity: {name} at an extreme position") for i, name in enumerate(inputs)]


def singularity_figure(analysis, plane, table, inputs, couples, resolution, robot_name):
    extent = workspace_extent(plane, table["inside"])
    limited = any(name.startswith("admissible_") for name in table)
    handles = [Patch(color=SIGN_FILL[1], label="det J_DKP > 0"), Patch(color=SIGN_FILL[-1], label="det J_DKP < 0"),
               Line2D([], [], color="black", linewidth=1.5, label="DKP singularity (det J_DKP = 0)")]
    if limited:
        handles.append(Line2D([], [], color="dimgrey", linestyle="dashed", label="a limit of the robot"))
    handles += ikp_handles(inputs)
    layout = Layout(len(analysis.modes), panel_size(extent), math.ceil(len(handles) / 3))
    figure, axes = layout.panels()
    for n, (axis, mode) in enumerate(zip(axes, analysis.modes)):
        measure = table[f"measure_{mode}"].copy()
        if limited:
            measure[table[f"admissible_{mode}"] < 0.5] = np.nan
        colours = np.ones(measure.shape + (3,))
        for sign, colour in SIGN_FILL.items():
            colours[np.sign(measure) == sign] = to_rgb(colour)
        axis.imshow(colours, origin="lower", extent=lattice_extent(plane, resolution), interpolation="nearest")
        if np.nanmin(measure, initial=0) < 0 < np.nanmax(measure, initial=0):
            axis.contour(plane.us, plane.vs, measure, levels=[0], colors="black", linewidths=1.3)
        if limited:
            axis.contour(plane.us, plane.vs, table[f"admissible_{mode}"], levels=[0.5], colors="dimgrey",
                         linewidths=1.2, linestyles="dashed")
        draw_ikp_boundary(axis, plane, table, inputs, couples)
        axis.set_title(mode_title(analysis, mode))
        label_axes(axis, plane, extent, n % layout.columns == 0, n >= len(axes) - layout.columns)
    layout.frame(figure, f"{robot_name}: singularity loci of each working mode (WM) on the plane {plane.title}",
                 f"mow eval on poses {resolution * 1000:g} mm apart; white: outside the workspace"
                 f"{' or beyond a limit of the robot' if limited else ''}; the workspace boundary is where the "
                 "chains of one input reach an extreme position", handles, 3)
    return figure


def region_names(analysis, mode):
    """Region id -> ('+1', colour), ...: the mode's non-debris regions numbered per sign by
    decreasing volume."""
    names = {}
    for sign, symbol in ((1, "+"), (-1, "\u2212")):
        ranked = sorted((r for r in analysis.regions.values() if r["mode"] == mode and r["sign"] == sign
                         and not r["debris"]), key=lambda r: -r["voxels"])
        for rank, region in enumerate(ranked):
            names[region["id"]] = (f"{symbol}{rank + 1}", REGION_COLOURS[sign][rank % len(REGION_COLOURS[sign])])
    return names


def erode(mask):
    """The cells of the mask whose four neighbours are in it too."""
    eroded = mask.copy()
    eroded[1:] &= mask[:-1]
    eroded[:-1] &= mask[1:]
    eroded[:, 1:] &= mask[:, :-1]
    eroded[:, :-1] &= mask[:, 1:]
    eroded[[0, -1]] = False
    eroded[:, [0, -1]] = False
    return eroded


def wide(mask):
    """At least three cells across somewhere."""
    return erode(mask).any()


def innermost_cell(mask):
    """A cell of the mask as far from its edges as erosion finds, nearest the centre of
    what is left: where a name on the region is readable."""
    eroded = erode(mask)
    while eroded.any():
        mask, eroded = eroded, erode(eroded)
    rows, columns = np.nonzero(mask)
    nearest = np.argmin((rows - rows.mean()) ** 2 + (columns - columns.mean()) ** 2)
    return rows[nearest], columns[nearest]


def regions_figure(analysis, plane, table, step, robot_name):
    extent = workspace_extent(plane, table["inside"])
    handles = [Patch(color=REGION_COLOURS[1][0], label="region of det J_DKP > 0 (+1: the largest)"),
               Patch(color=REGION_COLOURS[-1][0], label="region of det J_DKP < 0 (\u22121: the largest)"),
               Patch(color=DEBRIS_COLOUR, label="debris (components too small to count)"),
               Line2D([], [], color="black", linewidth=1, label="workspace boundary (IKP singularities)")]
    layout = Layout(len(analysis.modes), panel_size(extent), 2)
    figure, axes = layout.panels()
    minimum_cells = 0.005 * (np.asarray(table["inside"]) > 0.5).mean() * plane.labels[analysis.modes[0]].size
    for n, (axis, mode) in enumerate(zip(axes, analysis.modes)):
        labels = plane.labels[mode]
        names = region_names(analysis, mode)
        colours = np.ones(labels.shape + (3,))
        colours[labels >= 0] = to_rgb(DEBRIS_COLOUR)
        for region, (_, colour) in names.items():
            colours[labels == region] = to_rgb(colour)
        axis.imshow(colours, origin="lower", extent=plane.cell_extent, interpolation="nearest")
        axis.contour(plane.us, plane.vs, table["inside"], levels=[0.5], colors="black", linewidths=0.8)
        xs, ys = cell_centres(plane, labels.shape, step)
        for region, (name, _) in names.items():
            mask = labels == region
            # Slivers get no name: it would hide them.
            if mask.sum() >= minimum_cells and wide(mask):
                row, column = innermost_cell(mask)
                axis.text(xs[column], ys[row], name, ha="center", va="center", fontsize=12, fontweight="bold",
                          color="white", path_effects=[withStroke(linewidth=2.5, foreground="black")])
        axis.set_title(mode_title(analysis, mode))
        label_axes(axis, plane, extent, n % layout.columns == 0, n >= len(axes) - layout.columns)
    layout.frame(figure, f"{robot_name}: singularity-free regions of each working mode (WM) on the plane {plane.title}",
                 f"grid cells of {step * 1000:g} mm from mow workspace; a region is a 3-D component, so it may cut the "
                 "plane more than once; white inside the boundary: cells on a DKP singularity", handles, 2)
    return figure


def maximal_figure(analysis, plane, table, points, inputs, step, robot_name):
    extent = workspace_extent(plane, table["inside"])
    handles = [Patch(color=OUTSIDE_MAXIMAL, label="workspace outside the maximal one (debris, singular cells)"),
               Patch(facecolor="none", edgecolor="black", hatch="//", linestyle="dashed", linewidth=1.5,
                     label="traditional workspace (the region holding the start)")]
    handles += [Line2D([], [], color=INPUT_COLOURS[i % len(INPUT_COLOURS)], marker="o", linestyle="none",
                       label=f"transition points: {name} changes branch") for i, name in enumerate(inputs)]
    layout = Layout(2, panel_size(extent, widest=5.4, tallest=6.0), math.ceil(len(handles) / 2), right=1.5,
                    columns=2, gaps=(0.4, 0.85))
    figure, axes = layout.panels()
    positions, point_inputs, served = points
    near = np.abs(positions[:, plane.axis] - plane.value) <= step / 2
    # One colour per count from 1, the lightest still apart from the white outside.
    count_colours = ListedColormap(plt.get_cmap("YlGn")(np.linspace(0.25, 1.0, len(analysis.modes))))
    for n, (axis, sign) in enumerate(zip(axes, (-1, 1))):
        shape = plane.labels[analysis.modes[0]].shape
        count, anywhere = np.zeros(shape, dtype=int), np.zeros(shape, dtype=bool)
        for mode in analysis.modes:
            labels = plane.labels[mode]
            anywhere |= labels >= 0
            count += np.isin(labels, [r for r in np.unique(labels[labels >= 0])
                                      if analysis.regions[r]["sign"] == sign and not analysis.regions[r]["debris"]])
        colours = np.ones(shape + (4,))
        colours[anywhere] = to_rgba(OUTSIDE_MAXIMAL)
        colours[count > 0] = count_colours(count[count > 0] - 1)
        axis.imshow(colours, origin="lower", extent=plane.cell_extent, interpolation="nearest")
        axis.contour(plane.us, plane.vs, table["inside"], levels=[0.5], colors="black", linewidths=0.8)
        traditional = analysis.assembly[sign]["traditional_region"]
        if traditional >= 0:
            mine = plane.labels[analysis.regions[traditional]["mode"]] == traditional
            if mine.any():
                centres = cell_centres(plane, shape, step)
                # Hatched as well as outlined: an outline alone does not say which side it is.
                axis.contourf(*centres, mine.astype(float), levels=[0.5, 1.5], colors="none", hatches=["//"])
                axis.contour(*centres, mine.astype(float), levels=[0.5], colors="black", linewidths=2.2,
                             linestyles="dashed")
        transitions = analysis.summary["transitions"]
        joins = np.array([any(transitions[t]["sign"] == sign and not transitions[t]["between_debris"] for t in s)
                          for s in served], dtype=bool).reshape(-1)
        for i in range(len(inputs)):
            chosen = near & joins & (point_inputs == i)
            axis.plot(positions[chosen, plane.u], positions[chosen, plane.v], "o", markersize=3.5,
                      color=INPUT_COLOURS[i % len(INPUT_COLOURS)])
        summary = analysis.assembly[sign]
        mode = analysis.regions[traditional]["mode"] if traditional >= 0 else "none"
        axis.set_title(f"assembly mode {'+' if sign > 0 else chr(0x2212)} (det J_DKP {'>' if sign > 0 else '<'} 0)\n"
                       f"maximal {100 * summary['maximal_fraction']:.1f} %, traditional "
                       f"{100 * summary['traditional_fraction']:.1f} % (WM {mode})", fontsize=11)
        label_axes(axis, plane, extent, n == 0, True)
    left = layout.adjust["right"] + 0.25 / layout.size[0]
    bar_axis = figure.add_axes([left, layout.adjust["bottom"], 0.18 / layout.size[0],
                                layout.adjust["top"] - layout.adjust["bottom"]])
    scalar = plt.cm.ScalarMappable(cmap=count_colours, norm=plt.Normalize(0.5, len(analysis.modes) + 0.5))
    bar = figure.colorbar(scalar, cax=bar_axis, ticks=range(1, len(analysis.modes) + 1))
    bar.set_label("working modes whose region covers the cell")
    layout.frame(figure, f"{robot_name}: maximal operational workspaces on the plane {plane.title}",
                 "union over all working modes of the regions of one sign of det J_DKP (grid cells of "
                 f"{step * 1000:g} mm); transition points within half a cell of the plane; fractions of the whole "
                 "workspace", handles, 2)
    return figure


def read_plan(path, inputs):
    """The plan file (docs/ros.md, mow plan): positions, working mode per sample, times and
    inputs (one column each), and its transitions as (sample, input index, from mode, to
    mode)."""
    with open(path, newline="") as source:
        rows = list(csv.DictReader(source))
    positions = np.array([[float(r["x"]), float(r["y"]), float(r["z"])] for r in rows])
    modes = [r["mode"] for r in rows]
    times = np.array([float(r["t"]) for r in rows])
    values = np.array([[float(r[name]) for name in inputs] for r in rows])
    transitions = []
    for k in range(1, len(rows)):
        if modes[k] != modes[k - 1]:
            # The transition point is the first sample in the new mode (arrival and departure share it).
            changed = [i for i in range(len(inputs)) if modes[k][i] != modes[k - 1][i]]
            transitions.append((k, changed[0], modes[k - 1], modes[k]))
    return positions, modes, transitions, times, values


def transition_label(transition, inputs):
    _, i, before, after = transition
    return f"{inputs[i]} {before[i]}\u2192{after[i]}"


def path_figure(analysis, plan, plan_sign, projections, extents, transition_planes, inputs, couples, units, step,
                robot_name):
    positions, modes, transitions, times, values = plan
    used = list(dict.fromkeys(modes))
    colour = {mode: MODE_COLOURS[analysis.modes.index(mode) % len(MODE_COLOURS)] for mode in used}
    # Runs of one working mode as (mode, first sample, end): each run goes on to the
    # transition point that starts the next, so the line is unbroken.
    runs, first = [], 0
    for k in range(1, len(modes) + 1):
        if k == len(modes) or modes[k] != modes[first]:
            runs.append((modes[first], first, min(k + 1, len(modes))))
            first = k
    symbol = "+" if plan_sign > 0 else "\u2212"
    columns = max(3, len(transitions) + 1)
    handles = [Line2D([], [], color=colour[m], linewidth=3, label=f"path in WM {m}") for m in used]
    if transitions:
        handles.append(Line2D([], [], color="black", marker="*", markersize=13, linestyle="none",
                              label="transition: the input changes branch at an IKP singularity"))
        handles += ikp_handles(inputs)
    legend_columns = 3
    layout = Layout(2 * columns, (4.3, 4.3), math.ceil(len(handles) / legend_columns), columns=columns,
                    gaps=(0.9, 1.1))
    figure = plt.figure(figsize=layout.size)
    grid = figure.add_gridspec(2, columns, **layout.adjust)
    # A label on each side in turn: transitions often lie close together.
    sides = [(-10, 8, "right"), (10, -16, "left")]

    space = figure.add_subplot(grid[0, 0], projection="3d")
    for mode, a, b in runs:
        space.plot(*positions[a:b].T, color=colour[mode], linewidth=2.5)
    for n, t in enumerate(transitions):
        space.scatter(*positions[t[0]], marker="*", s=220, color="black", depthshade=False)
        space.text(*positions[t[0]], f"  {transition_label(t, inputs)}  ", fontsize=10, ha=sides[n % 2][2])
    for k, name in ((0, "p_i"), (len(positions) - 1, "p_f")):
        space.scatter(*positions[k], s=50, color="black", depthshade=False)
        space.text(*positions[k], f"  ${name}$", fontsize=13)
    space.set_box_aspect(np.ptp(positions, axis=0) + 0.05)
    for name, setter in zip(AXES, (space.set_xlabel, space.set_ylabel, space.set_zlabel)):
        setter(f"{name} (m)")
    space.set_title("the path in space", fontsize=12)

    for column, normal in ((1, 2), (2, 1)):
        axis = figure.add_subplot(grid[0, column])
        u, v = PLANE_AXES[normal]
        axis.imshow(np.where(projections[normal], 0.86, 1.0), origin="lower", extent=extents[normal], cmap="gray",
                    vmin=0, vmax=1, interpolation="nearest")
        for mode, a, b in runs:
            axis.plot(positions[a:b, u], positions[a:b, v], color=colour[mode], linewidth=2.5)
        for n, t in enumerate(transitions):
            dx, dy, align = sides[n % 2]
            axis.plot(positions[t[0], u], positions[t[0], v], "*", color="black", markersize=14)
            axis.annotate(transition_label(t, inputs), positions[t[0], [u, v]], xytext=(dx, dy),
                          textcoords="offset points", ha=align, fontsize=10,
                          path_effects=[withStroke(linewidth=3, foreground="white")])
        for k, name in ((0, "p_i"), (len(positions) - 1, "p_f")):
            axis.plot(positions[k, u], positions[k, v], "o", color="black")
            axis.annotate(f"${name}$", positions[k, [u, v]], xytext=(6, 6), textcoords="offset points", fontsize=13)
        # The silhouette and the path, not the whole box.
        rows, cells = np.nonzero(projections[normal])
        side = (extents[normal][1] - extents[normal][0]) / projections[normal].shape[1]
        low = np.minimum([extents[normal][0] + cells.min() * side, extents[normal][2] + rows.min() * side],
                         positions[:, [u, v]].min(axis=0)) - 0.03
        high = np.maximum([extents[normal][0] + (cells.max() + 1) * side, extents[normal][2] + (rows.max() + 1) * side],
                          positions[:, [u, v]].max(axis=0)) + 0.03
        axis.set_xlim(low[0], high[0])
        axis.set_ylim(low[1], high[1])
        axis.set_aspect("equal")
        axis.set_xlabel(f"{AXES[u]} (m)")
        axis.set_ylabel(f"{AXES[v]} (m)")
        axis.set_title(f"seen along {AXES[normal]}, over the maximal workspace ({symbol}, grey)", fontsize=11)

    # Bottom row: the plane z through each transition, where a region of each working mode
    # reaches the IKP singularity of the input that changes branch.
    for column, (t, (plane, table)) in enumerate(zip(transitions, transition_planes)):
        axis = figure.add_subplot(grid[1, column])
        k, i, before, after = t
        shape = plane.labels[before].shape
        inside = {}
        for mode in (before, after):
            labels = plane.labels[mode]
            inside[mode] = np.isin(labels, [r for r in np.unique(labels[labels >= 0])
                                            if analysis.regions[r]["sign"] == plan_sign
                                            and not analysis.regions[r]["debris"]])
        tint = {mode: 0.5 + 0.5 * np.array(to_rgb(colour[mode])) for mode in (before, after)}
        image = np.ones(shape + (3,))
        image[inside[before]] = tint[before]
        image[inside[after]] = tint[after]
        image[inside[before] & inside[after]] = (tint[before] + tint[after]) / 2 * 0.85
        axis.imshow(image, origin="lower", extent=plane.cell_extent, interpolation="nearest")
        draw_ikp_boundary(axis, plane, table, inputs, couples, linewidth=2.5)
        for mode, a, b in runs:
            if (mode, b) == (before, k + 1) or (mode, a) == (after, k):
                leg = positions[a:b]
                axis.plot(leg[:, 0], leg[:, 1], ":", color=colour[mode], linewidth=1.5)
                # Solid only near the plane: elsewhere the leg is above or below what is drawn.
                near = np.where(np.abs(leg[:, 2] - plane.value) <= SLAB, leg[:, 1], np.nan)
                axis.plot(leg[:, 0], near, color=colour[mode], linewidth=3)
        axis.plot(positions[k, 0], positions[k, 1], "*", color="black", markersize=18)
        centre = positions[k, :2]
        axis.set_xlim(centre[0] - 0.25, centre[0] + 0.25)
        axis.set_ylim(centre[1] - 0.25, centre[1] + 0.25)
        axis.set_aspect("equal")
        axis.set_xlabel("x (m)")
        axis.set_ylabel("y (m)")
        axis.set_title(f"transition {column + 1}: {transition_label(t, inputs)} ({before} \u2192 {after})\n"
                       f"on the plane {plane.title}", fontsize=11)
        axis.legend(handles=[Patch(color=tint[before], label=f"{before} only"),
                             Patch(color=tint[after], label=f"{after} only"),
                             Patch(color=(tint[before] + tint[after]) / 2 * 0.85, label="both")],
                    loc="lower left", fontsize=9, framealpha=0.9)
    axis = figure.add_subplot(grid[1, len(transitions)])
    for i, name in enumerate(inputs):
        axis.plot(times, values[:, i], color=INPUT_COLOURS[i % len(INPUT_COLOURS)], linewidth=2.2,
                  label=f"{name} ({units[name]})")
    for t in transitions:
        axis.axvline(times[t[0]], color="black", linestyle=":", linewidth=1.2)
        axis.annotate(transition_label(t, inputs), (times[t[0]], 1), xycoords=("data", "axes fraction"),
                      xytext=(-4, -6), textcoords="offset points", ha="right", va="top", fontsize=10, rotation=90)
    axis.set_xlabel("time (s)")
    axis.set_ylabel(f"input ({' or '.join(sorted(set(units.values()), reverse=True))})")
    axis.set_title("the actuators' inputs along the plan", fontsize=11)
    axis.legend(loc="lower left", fontsize=9)
    changes = (f"changes working mode at {len(transitions)} IKP singularities, as in the chapter's Fig. 14"
               if transitions else f"keeps working mode {used[0]}")
    layout.frame(figure, f"{robot_name}: a path through the maximal operational workspace ({symbol}) that {changes}",
                 f"mow plan on a {step * 1000:g} mm grid, from $p_i$ to $p_f$" +
                 (f"; bottom: regions ({symbol}) of the two working modes of each transition on the plane through "
                  f"it, and the path's legs projected on it (solid within {SLAB * 100:g} cm of the plane)"
                  if transitions else ""),
                 handles, legend_columns)
    return figure


def plan_demo(mow, demo, inputs, plan_file):
    """mow plan from the demo file's start to its goal: (read_plan's tuple, assembly mode
    sign), or (None, None) when mow finds no plan."""
    try:
        ends = yaml.safe_load(Path(demo).read_text())
    except OSError as error:
        fail(f"{demo}: {error.strerror}")
    if not isinstance(ends, dict) or not {"start", "goal"} <= ends.keys():
        fail(f"{demo}: expected start: [x, y, z] and goal: [x, y, z] (m), as in config/demo/")
    done = mow.run("plan", *mow.analysis_options, "--from", ",".join(map(repr, ends["start"])),
                   "--goal", ",".join(map(repr, ends["goal"])), "--out", str(plan_file), "--quiet", allowed=(0, 3))
    if done.returncode != 0:
        print(f"no path figure: {done.stdout.strip().splitlines()[-1]}")
        return None, None
    sign = re.search(r"assembly mode ([+-])", done.stdout)
    if not sign:
        fail(f"mow plan did not name the plan's assembly mode:\n{done.stdout}")
    return read_plan(plan_file, inputs), 1 if sign.group(1) == "+" else -1


def main():
    started = time.monotonic()
    arguments = parse_arguments()
    mow = Mow(find_mow(arguments.mow), arguments.robot, arguments.step, arguments.cache)
    inputs, couples, units = robot_inputs(arguments.robot)
    robot_name = Path(arguments.robot).stem
    demo = arguments.demo or str(REPO / "config" / "demo" / f"{robot_name}.yaml")
    out_dir = Path(arguments.out_dir)
    written = []

    def save(figure, name):
        path = out_dir / name
        out_dir.mkdir(parents=True, exist_ok=True)
        figure.savefig(path, dpi=arguments.dpi)
        plt.close(figure)
        written.append(path)

    with tempfile.TemporaryDirectory(prefix="chapter_figures_") as scratch:
        scratch = Path(scratch)
        mow.run("workspace", *mow.analysis_options, "--out", str(scratch / "analysis"), "--quiet")
        analysis = Analysis(scratch / "analysis")
        middle = [sum(analysis.grid["bounds"][axis]) / 2 for axis in range(3)]
        planes = [Plane(axis, value, analysis.grid, arguments.resolution)
                  for axis, value in arguments.planes or [(2, middle[2]), (0, middle[0])]]

        plan, plan_sign = None, None
        if arguments.demo or Path(demo).is_file():
            plan, plan_sign = plan_demo(mow, demo, inputs, scratch / "plan.csv")
        # The plane z through each transition, where the path figure shows it.
        transition_planes = [Plane(2, plan[0][t[0], 2], analysis.grid, arguments.resolution)
                             for t in plan[2]] if plan else []

        projections, extents = analysis.read_regions(planes + transition_planes, plan_sign)
        points = analysis.transition_points()
        for plane in planes:
            table = evaluate(mow, plane, scratch)
            save(singularity_figure(analysis, plane, table, inputs, couples, arguments.resolution, robot_name),
                 f"chapter_singularities_{plane.name}.png")
            save(regions_figure(analysis, plane, table, arguments.step, robot_name),
                 f"chapter_regions_{plane.name}.png")
            save(maximal_figure(analysis, plane, table, points, inputs, arguments.step, robot_name),
                 f"chapter_maximal_{plane.name}.png")
        if plan:
            tables = [(plane, evaluate(mow, plane, scratch)) for plane in transition_planes]
            save(path_figure(analysis, plan, plan_sign, projections, extents, tables, inputs, couples, units,
                             arguments.step, robot_name), "chapter_path.png")
    for path in written:
        print(f"wrote {path}")
    print(f"{len(written)} figures in {time.monotonic() - started:.1f} s")


if __name__ == "__main__":
    main()
