#!/usr/bin/python3
"""The launch files as a user meets them: `roslaunch --ros-args` lists no argument of any
launch file as required (each has a default), and rviz.launch, directly or through
demo.launch, starts rviz on the desktop by default and on its own Xvfb screen
(rviz_headless.sh) when given a display file; robot_display.launch alone shows the
delta-like robot.

Run by catkin as a rosunit test (JUnit file from --gtest_output=xml:FILE), or by hand in a
built workspace: /usr/bin/python3 test/test_launch_files.py --text"""
import subprocess
import sys
import unittest
from pathlib import Path

import roslaunch.config
import rosunit

LAUNCH = Path(__file__).resolve().parent.parent / "launch"


def nodes(launch_file, *args):
    """(package, type, args) of every node the launch file starts with these arguments."""
    config = roslaunch.config.load_config_default([(str(LAUNCH / launch_file), list(args))], None, verbose=False)
    return config, [(node.package, node.type, node.args) for node in config.nodes]


class LaunchFiles(unittest.TestCase):
    def test_no_argument_is_listed_as_required(self):
        files = sorted(LAUNCH.glob("*.launch"))
        self.assertGreaterEqual(len(files), 5)
        for launch_file in files:
            listed = subprocess.run(["roslaunch", "--ros-args", str(launch_file)], capture_output=True, text=True)
            self.assertEqual(listed.returncode, 0, f"{launch_file.name}: {listed.stderr}")
            self.assertIn("Optional Arguments:", listed.stdout, launch_file.name)
            self.assertNotIn("Required Arguments:", listed.stdout, f"{launch_file.name}:\n{listed.stdout}")

    def test_rviz_on_the_desktop_unless_given_a_display_file(self):
        for launch_file, extra in (("rviz.launch", []), ("demo.launch", ["step:=0.02"])):
            _, started = nodes(launch_file, *extra)
            self.assertEqual([node[:2] for node in started if "rviz" in node[1]], [("rviz", "rviz")], launch_file)
            _, started = nodes(launch_file, "headless_display_file:=/tmp/mow_display", *extra)
            rviz = [node for node in started if "rviz" in node[1]]
            self.assertEqual(len(rviz), 1, launch_file)
            self.assertEqual(rviz[0][:2], ("maximal_workspace", "rviz_headless.sh"), launch_file)
            self.assertTrue(rviz[0][2].startswith("/tmp/mow_display -d "), rviz[0][2])

    def test_robot_display_alone_shows_the_delta_like_robot(self):
        config, _ = nodes("robot_display.launch")
        self.assertIn('<robot name="delta_like"', config.params["/robot_description"].value)


if __name__ == "__main__":
    rosunit.unitrun("maximal_workspace", "test_launch_files", LaunchFiles, sys.argv)
