#!/usr/bin/python3
"""scripts/plot_chapter_figures.py on a coarse grid (a 20 mm analysis, poses 10 mm apart,
its own mow cache): it writes the three figures of each plane and the path figure as PNG
images, names them in its output, and refuses a plane outside the analysis's box with the
reason. mow is the built one (MOW_BINARY, else what the script finds itself).

Run by catkin as a rosunit test (JUnit file from --gtest_output=xml:FILE), or by hand:
/usr/bin/python3 test/test_plot_chapter_figures.py --text"""
import os
import re
import struct
import subprocess
import sys
import tempfile
import unittest
from pathlib import Path

import rosunit

SCRIPT = Path(__file__).resolve().parent.parent / "scripts" / "plot_chapter_figures.py"
PNG_SIGNATURE = b"\x89PNG\r\n\x1a\n"


def png_size(path):
    """Width and height from the PNG's IHDR chunk, which follows the signature."""
    data = path.read_bytes()[:24]
    if not data.startswith(PNG_SIGNATURE) or data[12:16] != b"IHDR":
        return None
    return struct.unpack(">II", data[16:24])


class PlotChapterFigures(unittest.TestCase):
    def setUp(self):
        self.scratch = tempfile.TemporaryDirectory(prefix="test_plot_chapter_figures_")
        self.folder = Path(self.scratch.name)

    def tearDown(self):
        self.scratch.cleanup()

    def run_script(self, *arguments):
        mow = ["--mow", os.environ["MOW_BINARY"]] if os.environ.get("MOW_BINARY") else []
        return subprocess.run(["/usr/bin/python3", str(SCRIPT), "--step", "0.02", "--resolution", "0.01",
                               "--cache", str(self.folder / "cache"), *mow, *arguments],
                              capture_output=True, text=True, timeout=600)

    def test_writes_every_figure_as_a_png(self):
        out = self.folder / "images"
        done = self.run_script("--out-dir", str(out), "--plane", "z=0.2", "--plane", "y=0.3")
        self.assertEqual(done.returncode, 0, done.stderr)
        written = {Path(p).name for p in re.findall(r"^wrote (.+)$", done.stdout, re.MULTILINE)}
        self.assertEqual(written, {p.name for p in out.iterdir()}, done.stdout)
        for kind in ("singularities", "regions", "maximal"):
            for axis in "zy":
                self.assertEqual(len([n for n in written if n.startswith(f"chapter_{kind}_{axis}_")]), 1,
                                 f"chapter_{kind}_{axis}_*.png in {sorted(written)}")
        self.assertIn("chapter_path.png", written)
        self.assertEqual(len(written), 7)
        for name in written:
            size = png_size(out / name)
            self.assertIsNotNone(size, f"{name} is not a PNG")
            self.assertGreater(min(size), 400, f"{name} is only {size[0]} x {size[1]} pixels")

    def test_a_plane_outside_the_box_is_refused_with_the_reason(self):
        done = self.run_script("--out-dir", str(self.folder / "images"), "--plane", "z=5")
        self.assertNotEqual(done.returncode, 0)
        self.assertIn("outside the analysis's box", done.stderr)
        self.assertFalse((self.folder / "images").exists() and any((self.folder / "images").iterdir()))


if __name__ == "__main__":
    rosunit.unitrun("maximal_workspace", "test_plot_chapter_figures", PlotChapterFigures, sys.argv)
