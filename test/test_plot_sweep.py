#!/usr/bin/python3
"""scripts/plot_sweep.py on a small results file of known values (no mow needed): a heat
map and a line as PNG images of the size asked for, the best design named, a row cut
mid-way ignored, and bad input (an unknown column, a file that is not a study's results)
refused with a message that says what is wrong.

Run by catkin as a rosunit test (JUnit file from --gtest_output=xml:FILE), or by hand:
/usr/bin/python3 test/test_plot_sweep.py --text"""
import subprocess
import sys
import tempfile
import unittest
from pathlib import Path

import rosunit

from test_plot_chapter_figures import png_size

SCRIPT = Path(__file__).resolve().parent.parent / "scripts" / "plot_sweep.py"
# A 3 x 2 grid as mow sweep writes it: one design that does not load, whose reason holds
# commas in quotes; design 5 has the largest maximal volume, design 3 the fewest seconds.
RESULTS = """# study: 0123456789abcdef
design,"scale(chains[KC2a,KC2b].rod_length)",kc3,status,workspace_volume,maximal_volume_positive,seconds,reason
0,0.9,0.8,invalid_robot,,,,"robot.yaml:67: reference: chain 'KC2a' cannot be assembled, discriminant < 0"
1,0.9,1,ok,0.5,0.45,0.2,
4,1.1,0.8,ok,0.7,0.65,0.4,
2,1,0.8,ok,0.6,0.55,0.3,
3,1,1,ok,0.8,0.75,0.1,
5,1.1,1,ok,0.9,0.85,0.25,
"""


class PlotSweep(unittest.TestCase):
    def setUp(self):
        self.scratch = tempfile.TemporaryDirectory(prefix="test_plot_sweep_")
        self.folder = Path(self.scratch.name)
        self.csv = self.folder / "study.csv"
        self.csv.write_text(RESULTS)

    def tearDown(self):
        self.scratch.cleanup()

    def run_script(self, *arguments, csv=None):
        return subprocess.run(["/usr/bin/python3", str(SCRIPT), str(csv or self.csv), *arguments],
                              capture_output=True, text=True, timeout=120)

    def test_heat_map_over_two_parameters(self):
        out = self.folder / "heat.png"
        done = self.run_script("--x", "chains[KC2a,KC2b].rod_length", "--y", "kc3", "--out", str(out))
        self.assertEqual(done.returncode, 0, done.stderr)
        self.assertEqual(png_size(out), (800, 600))
        self.assertIn("maximal_volume_positive of 5 ok designs out of 6", done.stdout)
        self.assertIn("the largest 0.85 at design 5 (scale(chains[KC2a,KC2b].rod_length) = 1.1, kc3 = 1)",
                      done.stdout)

    def test_line_against_one_parameter(self):
        out = self.folder / "line.png"
        done = self.run_script("--x", "kc3", "--figure", "seconds", "--dpi", "50", "--out", str(out))
        self.assertEqual(done.returncode, 0, done.stderr)
        self.assertEqual(png_size(out), (400, 300))
        self.assertIn("the fewest 0.1 at design 3", done.stdout)

    def test_a_row_cut_mid_way_is_ignored(self):
        cut = self.folder / "cut.csv"
        cut.write_text(RESULTS + "6,1.2,0.8,ok,0.9")  # as a run killed while writing it leaves it
        done = self.run_script("--x", "kc3", "--out", str(self.folder / "cut.png"), csv=cut)
        self.assertEqual(done.returncode, 0, done.stderr)
        self.assertIn("of 5 ok designs out of 6", done.stdout)

    def test_an_unknown_column_is_refused_naming_the_columns(self):
        out = self.folder / "unknown.png"
        done = self.run_script("--x", "kc4", "--out", str(out))
        self.assertNotEqual(done.returncode, 0)
        self.assertIn("--x 'kc4': no such parameter in", done.stderr)
        self.assertIn("its parameters: scale(chains[KC2a,KC2b].rod_length), kc3", done.stderr)
        done = self.run_script("--x", "kc3", "--figure", "maximal_volume", "--out", str(out))
        self.assertNotEqual(done.returncode, 0)
        self.assertIn("--figure 'maximal_volume': not a column", done.stderr)
        self.assertIn("its figures: workspace_volume, maximal_volume_positive, seconds", done.stderr)
        self.assertFalse(out.exists())

    def test_a_file_that_is_not_a_studys_results_is_refused(self):
        other = self.folder / "poses.csv"
        other.write_text("x,y,z\n0.1,0.2,0.3\n")
        done = self.run_script("--x", "x", "--out", str(self.folder / "poses.png"), csv=other)
        self.assertNotEqual(done.returncode, 0)
        self.assertIn("not a results file of mow sweep", done.stderr)


if __name__ == "__main__":
    rosunit.unitrun("maximal_workspace", "test_plot_sweep", PlotSweep, sys.argv)
