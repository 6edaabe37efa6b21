#!/usr/bin/python3
"""The demo in rviz, headless (rviz_demo.test): rviz runs on its own Xvfb screen
(scripts/rviz_headless.sh); once the workspace and the plan are published and the robot has
played the plan to its end, the screen is grabbed to PNG and its pixels must show the robot,
the workspace markers of at least two working modes and the planned path in the 3D view;
rviz's peak resident memory must stay under ~max_rviz_bytes at any grid step.
The colours looked for are the ones the nodes publish (the markers' colours, the URDF's
robot material), not copies of them."""
import colorsys
import os
import shutil
import subprocess
import sys
import time
import unittest
import xml.etree.ElementTree as ElementTree

import rospy
import rostest
from maximal_workspace.msg import PlannedPath
from PIL import Image
from sensor_msgs.msg import JointState
from visualization_msgs.msg import Marker, MarkerArray

BACKGROUND = (48, 48, 48)  # rviz/maximal_workspace.rviz: Background Color
ENABLED_NAMESPACE = "maximal_positive"  # the workspace namespace the config shows


def hue_degrees(rgb):
    return 360.0 * colorsys.rgb_to_hsv(*rgb)[0]


def hue_distance(a, b):
    d = abs(a - b) % 360.0
    return min(d, 360.0 - d)


def view_box(image):
    """The 3D view: the columns and rows mostly of rviz's background colour (a few panel
    pixels elsewhere may share it)."""
    rgb = image.convert("RGB")
    width, height = rgb.size
    pixels = rgb.load()
    columns, rows = [0] * width, [0] * height
    for y in range(0, height, 2):
        for x in range(0, width, 2):
            if pixels[x, y] == BACKGROUND:
                columns[x] += 1
                rows[y] += 1
    xs = [x for x in range(width) if columns[x] > 0.1 * height / 2]
    ys = [y for y in range(height) if rows[y] > 0.1 * width / 2]
    if not xs or not ys:
        return None
    return min(xs), min(ys), max(xs) + 1, max(ys) + 1


def analyse(image, robot_rgb, mode_rgbs, path_rgb):
    """What the 3D view shows: its box, the share of pixels that are not background, the
    robot's pixel count, per working mode the count of workspace pixels of its hue,
    and the count of opaque (saturated) pixels in the hue of the path's first line."""
    box = view_box(image)
    if box is None:
        return None
    view = image.convert("RGB").crop(box)
    robot_hue = hue_degrees(robot_rgb)
    mode_hues = {mode: hue_degrees(rgb) for mode, rgb in mode_rgbs.items()}
    path_hue = hue_degrees(path_rgb)
    drawn = robot = path = 0
    per_mode = {mode: 0 for mode in mode_rgbs}
    for r, g, b in view.getdata():
        if (r, g, b) == BACKGROUND:
            continue
        drawn += 1
        hue, saturation, value = colorsys.rgb_to_hsv(r / 255.0, g / 255.0, b / 255.0)
        hue *= 360.0
        if saturation > 0.6 and value > 0.45 and hue_distance(hue, robot_hue) < 10.0:
            robot += 1
        elif saturation > 0.75 and value > 0.45 and hue_distance(hue, path_hue) < 6.0:
            path += 1
        elif saturation > 0.08:  # faint cubes, or the lit surface, shaded
            for mode, mode_hue in mode_hues.items():
                if hue_distance(hue, mode_hue) < 8.0:
                    per_mode[mode] += 1
    return {"box": box, "drawn": drawn / float(view.size[0] * view.size[1]), "robot": robot, "modes": per_mode,
            "path": path}


def surface_hues(marker):
    """One vertex colour per hue (to 4 degrees) of a shaded surface: shading scales a colour,
    its hue stays."""
    by_hue = {}
    for c in marker.colors:
        by_hue.setdefault(round(hue_degrees((c.r, c.g, c.b)) / 4.0), (c.r, c.g, c.b))
    return list(by_hue.values())


def distinct_modes_seen(result, mode_rgbs, min_pixels):
    """Working modes with enough pixels, counting hues closer than 16 degrees once."""
    seen = []
    for mode in sorted(result["modes"], key=lambda m: -result["modes"][m]):
        hue = hue_degrees(mode_rgbs[mode])
        if result["modes"][mode] >= min_pixels and all(hue_distance(hue, hue_degrees(mode_rgbs[s])) >= 16.0 for s in seen):
            seen.append(mode)
    return seen


def peak_memory_bytes(pid):
    """The process's peak resident set (VmHWM), from /proc."""
    with open(f"/proc/{pid}/status") as status:
        for line in status:
            if line.startswith("VmHWM:"):
                return int(line.split()[1]) * 1024
    raise AssertionError(f"no VmHWM for process {pid}")


def robot_colour_from_urdf(urdf):
    for material in ElementTree.fromstring(urdf).iter("material"):
        colour = material.find("color")
        if material.get("name") == "robot" and colour is not None:
            return tuple(float(c) for c in colour.get("rgba").split()[:3])
    raise AssertionError("robot_description has no 'robot' material")


def display_name(display_file, deadline, test):
    """The Xvfb display rviz_headless.sh writes to display_file, once it has."""
    while not os.path.exists(display_file):
        test.assertLess(time.time(), deadline, "rviz_headless.sh never wrote " + display_file)
        time.sleep(0.2)
    with open(display_file) as f:
        return f.read().strip()


def grab_screen(display, artifact):
    """The screen as a PNG at artifact, opened."""
    grab = subprocess.run(["xwd", "-display", display, "-root", "-silent"], stdout=subprocess.PIPE, check=True)
    subprocess.run(["convert", "xwd:-", "png:" + artifact], input=grab.stdout, check=True)
    return Image.open(artifact)


def run_removing_server_cache(test_name, case):
    """rostest's run of the case, after which the server's cache goes with the test
    (hundreds of MB at 2 mm)."""
    try:
        rostest.rosrun("maximal_workspace", test_name, case, sys.argv)
    finally:
        cache = rospy.get_param("/workspace_server/cache_directory", "")
        if cache.startswith("/tmp/mow_"):
            shutil.rmtree(cache, ignore_errors=True)


class RvizDemo(unittest.TestCase):
    def test_view_shows_robot_and_workspace_of_two_working_modes(self):
        timeout = rospy.get_param("~timeout", 300.0)
        display_file = rospy.get_param("~display_file")
        artifact = rospy.get_param("~artifact")
        min_robot = rospy.get_param("~min_robot_pixels", 400)
        min_mode = rospy.get_param("~min_mode_pixels", 300)
        min_path = rospy.get_param("~min_path_pixels", 100)

        deadline = time.time() + timeout
        display = display_name(display_file, deadline, self)

        markers = rospy.wait_for_message("/maximal_workspace/markers", MarkerArray, timeout=timeout)
        plan = rospy.wait_for_message("/path_planner/plan", PlannedPath, timeout=timeout)
        self.assertGreater(len(plan.transitions), 0, "the demo's plan should change working mode")
        # The maximal workspace's surface carries the working modes' colours at its vertices,
        # shaded (one hue each), or with surfaces false a CUBE_LIST per working mode.
        surfaces = [m for m in markers.markers
                    if m.ns == ENABLED_NAMESPACE and m.type == Marker.TRIANGLE_LIST and m.points]
        mode_rgbs = (dict(enumerate(surface_hues(surfaces[0]))) if surfaces else {
            m.id: (m.color.r, m.color.g, m.color.b)
            for m in markers.markers
            if m.ns == ENABLED_NAMESPACE and m.type == Marker.CUBE_LIST and m.points
        })
        self.assertGreaterEqual(len(mode_rgbs), 2, "workspace markers of fewer than two working modes published")
        path_markers = rospy.wait_for_message("/path_planner/markers", MarkerArray, timeout=timeout)
        path_rgbs = [(m.color.r, m.color.g, m.color.b) for m in path_markers.markers
                     if m.ns == "path" and m.type == Marker.LINE_STRIP]
        self.assertGreater(len(path_rgbs), 0, "no path lines published")
        # The first line, in the start's working mode: the later ones may share their hue with
        # other saturated things on the screen (the demo's pnn orange does).
        robot_rgb = robot_colour_from_urdf(rospy.get_param("/robot_description"))
        # The demo plays the plan back: grab once the robot stands at the goal, so the picture
        # (kept for docs/) shows the end of the path.
        goal = plan.path.poses[-1].pose.position
        while True:
            state = rospy.wait_for_message("/joint_states", JointState, timeout=timeout)
            at = dict(zip(state.name, state.position))
            if all(abs(at.get("platform_" + axis, float("inf")) - getattr(goal, axis)) < 1e-9 for axis in "xyz"):
                break
            self.assertLess(time.time(), deadline, "the robot never reached the end of the plan")

        # rviz can lag seconds behind (it builds the marker geometry, and llvmpipe renders on the
        # CPU): grab until the view shows what is asked and two grabs 2 s apart agree.
        os.makedirs(os.path.dirname(artifact), exist_ok=True)
        result, seen, previous, grabs = None, [], None, 0
        render_deadline = time.time() + 120.0
        while time.time() < render_deadline:
            time.sleep(2.0)
            image = grab_screen(display, artifact)
            grabs += 1
            result = analyse(image, robot_rgb, mode_rgbs, path_rgbs[0])
            if result is None:
                continue
            view = image.convert("RGB").crop(result["box"]).tobytes()
            steady, previous = view == previous, view
            seen = distinct_modes_seen(result, mode_rgbs, min_mode)
            shown = result["robot"] >= min_robot and len(seen) >= 2 and result["path"] >= min_path
            if steady and result["drawn"] > 0.02 and shown:
                break
        print(f"rviz demo: screenshot {artifact} (grab {grabs}); view {result and result['box']}, "
              f"{result and round(100 * result['drawn'], 1)} % drawn, robot {result and result['robot']} px, "
              f"working-mode pixels {result and result['modes']}, distinct modes seen {seen}, "
              f"path {result and result['path']} px", file=sys.stderr)
        with open(display_file + ".pid") as f:
            rviz_pid = int(f.read().strip())
        peak = peak_memory_bytes(rviz_pid)
        max_bytes = float(rospy.get_param("~max_rviz_bytes", 1e9))
        markers_points = sum(len(m.points) for m in markers.markers)
        print(f"rviz demo: {markers_points} workspace marker points; rviz peak memory {peak / 1e6:.0f} MB "
              f"(limit {max_bytes / 1e6:.0f} MB)", file=sys.stderr)
        self.assertLess(peak, max_bytes, f"rviz's peak memory {peak / 1e6:.0f} MB")
        self.assertIsNotNone(result, "no 3D view (rviz background colour) on the screen: " + artifact)
        self.assertGreater(result["drawn"], 0.02, "the 3D view is blank: " + artifact)
        self.assertGreaterEqual(result["robot"], min_robot, "the robot is not in the 3D view: " + artifact)
        self.assertGreaterEqual(len(seen), 2, "fewer than two working modes' markers in the 3D view: " + artifact)
        self.assertGreaterEqual(result["path"], min_path, "the planned path is not in the 3D view: " + artifact)


if __name__ == "__main__":
    rospy.init_node("test_rviz_demo")
    run_removing_server_cache("rviz_demo", RvizDemo)
