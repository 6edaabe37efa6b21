#!/usr/bin/python3
"""An orientation set's coverage in rviz, headless (coverage_rviz.test): /compute_workspace
over a tilt-and-torsion envelope must answer total-orientation volumes where the maximal
workspace beats the traditional one, workspace_server must publish the heat map, and a
screenshot of rviz's 3D view must show it: pixels in the colours the markers carry (blue
for positions reaching few orientations, red for the surface of the positions reaching
all of them) and the colour bar's green middle."""
import colorsys
import os
import sys
import time
import unittest

import rospy
from maximal_workspace.srv import ComputeWorkspace, ComputeWorkspaceRequest
from visualization_msgs.msg import MarkerArray

from test_rviz_demo import display_name, grab_screen, hue_distance, run_removing_server_cache, view_box

MODES = ["nnnnnn", "pnnnnn", "npnnnn", "nnpnnn", "nnnpnn", "nnnnpn", "nnnnnp"]  # the start's and one branch away


def hsv_pixels(image, box):
    """(hue in degrees, saturation, value) of each pixel of the box."""
    for r, g, b in image.convert("RGB").crop(box).getdata():
        hue, saturation, value = colorsys.rgb_to_hsv(r / 255.0, g / 255.0, b / 255.0)
        yield 360.0 * hue, saturation, value


def coloured_pixels(image, box):
    """Saturated pixels of the 3D view near blue (240 deg), green (120) and red (0)."""
    counts = {"blue": 0, "green": 0, "red": 0}
    for hue, saturation, value in hsv_pixels(image, box):
        if saturation < 0.4 or value < 0.35:  # the bar's middle, (0.5, 1, 0.5), is 0.5 saturated
            continue
        for name, centre in (("blue", 240.0), ("green", 120.0), ("red", 0.0)):
            if hue_distance(hue, centre) < 15.0:
                counts[name] += 1
    return counts


def steady_counts(display, artifact, count, enough, seconds=120.0):
    """count(image, box) of the 3D view in screenshots at `artifact`, until the view is the
    same twice running and enough(counts), or `seconds` passed: rviz builds the markers and
    renders on the CPU. The last counts (None without a 3D view) and the view's box."""
    os.makedirs(os.path.dirname(artifact), exist_ok=True)
    counts, previous, box = None, None, None
    deadline = time.time() + seconds
    while time.time() < deadline:
        time.sleep(2.0)
        image = grab_screen(display, artifact)
        box = view_box(image)
        if box is None:
            continue
        counts = count(image, box)
        view = image.convert("RGB").crop(box).tobytes()
        steady, previous = view == previous, view
        if steady and enough(counts):
            break
    return counts, box


class CoverageRviz(unittest.TestCase):
    def test_heat_map_is_answered_published_and_shown(self):
        timeout = 300.0
        display_file = rospy.get_param("~display_file")
        artifact = rospy.get_param("~artifact")
        display = display_name(display_file, time.time() + timeout, self)

        rospy.wait_for_service("/compute_workspace", timeout=timeout)
        compute = rospy.ServiceProxy("/compute_workspace", ComputeWorkspace)
        envelope = 0.17453292519943295  # 10 deg
        response = compute(ComputeWorkspaceRequest(step=0.02, tilt_max=envelope, torsion=[-envelope, envelope],
                                                   angle_step=0.08726646259971647, working_modes=MODES))
        self.assertTrue(response.success, response.message)
        minus = [am for am in response.assembly_modes if am.sign == -1][0]
        # docs/results.md, "Orientation sets": 0.008992 against 0.007328 m^3 at 10 deg.
        self.assertGreater(minus.total_orientation_traditional_volume, 0.0)
        self.assertGreater(minus.total_orientation_volume, minus.total_orientation_traditional_volume)
        self.assertGreaterEqual(minus.inclusion_volume, minus.total_orientation_volume)
        self.assertTrue(any(name.endswith("coverage_negative.ot") for name in response.octree_files), response.octree_files)

        markers = rospy.wait_for_message("/maximal_workspace/markers", MarkerArray, timeout=timeout)
        heat = [m for m in markers.markers if m.ns == "coverage_negative"]
        self.assertEqual(len(heat), 1, "no heat map of assembly mode - published")
        self.assertEqual(len(heat[0].points), len(heat[0].colors))
        self.assertGreater(len(heat[0].points), 100)
        surface = [m for m in markers.markers if m.ns == "total_orientation_negative"]
        self.assertEqual(len(surface), 1, "no total-orientation surface of assembly mode - published")
        self.assertEqual(surface[0].type, surface[0].TRIANGLE_LIST)
        self.assertEqual(len(surface[0].points) % 3, 0)
        self.assertGreater(len(surface[0].points), 300)

        counts, box = steady_counts(display, artifact, coloured_pixels,
                                    lambda c: c["blue"] > 1000 and c["green"] > 50 and c["red"] > 2000)
        print(f"coverage rviz: screenshot {artifact}; view {box}, pixels {counts}", file=sys.stderr)
        self.assertIsNotNone(counts, "no 3D view on the screen: " + artifact)
        # rviz/compact.rviz shows the whole robot with its legend from 2.1 m: the heat map
        # covers about 2,000 blue pixels there (3,500 from 1.4 m, with the colour bar's).
        self.assertGreater(counts["blue"], 1000, "the heat map is not in the 3D view: " + artifact)
        self.assertGreater(counts["green"], 50, "the colour bar's middle is not in the 3D view: " + artifact)
        # The colour bar's top takes about 100 pixels: thousands are the surface.
        self.assertGreater(counts["red"], 2000, "the total-orientation surface is not in the 3D view: " + artifact)


if __name__ == "__main__":
    rospy.init_node("test_coverage_rviz")
    run_removing_server_cache("coverage_rviz", CoverageRviz)
