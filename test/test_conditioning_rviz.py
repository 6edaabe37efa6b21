#!/usr/bin/python3
"""The maximal workspace coloured by the conditioning index in rviz, headless
(conditioning_rviz.test): /compute_workspace with conditioning must answer the
well-conditioned volumes, workspace_server (colour_by_conditioning) must publish the
maximal surface in viridis colours with a colour bar in the legend, and a screenshot of
rviz's 3D view must show them: thousands of pixels in viridis's violet-to-blue low end (the
boundary is near singular, so most of it is low) and the bar's teal-to-yellow upper end."""
import sys
import time
import unittest

import rospy
from maximal_workspace.srv import ComputeWorkspace, ComputeWorkspaceRequest
from visualization_msgs.msg import MarkerArray

from test_coverage_rviz import hsv_pixels, steady_counts
from test_rviz_demo import display_name, hue_degrees, hue_distance, robot_colour_from_urdf, run_removing_server_cache

# Hue ranges (degrees) of matplotlib's viridis: its first five of nine control colours, dark
# violet (289) to blue (198), and its last four, teal (160) to yellow (54).
LOW_HUES, HIGH_HUES = (190.0, 300.0), (45.0, 185.0)


def viridis_pixels(image, box, robot_hue):
    """Saturated pixels of the 3D view in viridis's low and high hue ranges, but for the
    robot's own hue (its links are yellow-green)."""
    counts = {"low": 0, "high": 0}
    for hue, saturation, value in hsv_pixels(image, box):
        if saturation < 0.4 or value < 0.12 or hue_distance(hue, robot_hue) < 12.0:
            continue
        for name, (low, high) in (("low", LOW_HUES), ("high", HIGH_HUES)):
            if low <= hue <= high:
                counts[name] += 1
    return counts


class ConditioningRviz(unittest.TestCase):
    def test_conditioning_colours_are_answered_published_and_shown(self):
        timeout = 300.0
        display = display_name(rospy.get_param("~display_file"), time.time() + timeout, self)
        artifact = rospy.get_param("~artifact")

        rospy.wait_for_service("/compute_workspace", timeout=timeout)
        compute = rospy.ServiceProxy("/compute_workspace", ComputeWorkspace)
        response = compute(ComputeWorkspaceRequest(step=0.01, conditioning=True, conditioning_threshold=0.05))
        self.assertTrue(response.success, response.message)
        self.assertEqual(response.conditioning_threshold, 0.05)
        for am in response.assembly_modes:
            # A share of the maximal volume, and a mean of indices in [0, 1].
            self.assertGreater(am.well_conditioned_volume, 0.0)
            self.assertLessEqual(am.well_conditioned_volume, am.maximal_volume)
            self.assertGreater(am.global_conditioning_index, 0.0)
            self.assertLess(am.global_conditioning_index, 1.0)
        refused = compute(ComputeWorkspaceRequest(step=0.01, conditioning_threshold=1.5))
        self.assertFalse(refused.success)
        self.assertIn("conditioning_threshold", refused.message)

        markers = rospy.wait_for_message("/maximal_workspace/markers", MarkerArray, timeout=timeout)
        surface = [m for m in markers.markers if m.ns == "maximal_positive"]
        self.assertEqual(len(surface), 1, "no maximal surface of assembly mode + published")
        self.assertEqual(len(surface[0].colors), len(surface[0].points))
        legend = [m.text for m in markers.markers if m.ns == "legend"]
        self.assertIn("conditioning index", legend)
        self.assertFalse(any(text.startswith("working mode") for text in legend), legend)

        robot_hue = hue_degrees(robot_colour_from_urdf(rospy.get_param("/robot_description")))
        counts, box = steady_counts(display, artifact, lambda image, box: viridis_pixels(image, box, robot_hue),
                                    lambda c: c["low"] > 3000 and c["high"] > 100)
        print(f"conditioning rviz: screenshot {artifact}; view {box}, pixels {counts}", file=sys.stderr)
        self.assertIsNotNone(counts, "no 3D view on the screen: " + artifact)
        self.assertGreater(counts["low"], 3000, "the coloured surface is not in the 3D view: " + artifact)
        self.assertGreater(counts["high"], 100, "the colour bar's upper end is not in the 3D view: " + artifact)


if __name__ == "__main__":
    rospy.init_node("test_conditioning_rviz")
    run_removing_server_cache("conditioning_rviz", ConditioningRviz)
