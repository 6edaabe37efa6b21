#!/usr/bin/python3
"""docs/ros.md's Python action client (compute_workspace_client.test): the file
scripts/compute_workspace_client.py must be the one the docs quote, and run with rosrun
against workspace_server it must print feedback and a successful result."""
import os
import re
import subprocess
import unittest

import rospkg
import rospy

from test_rviz_demo import run_removing_server_cache

PACKAGE = rospkg.RosPack().get_path("maximal_workspace")
CLIENT = os.path.join(PACKAGE, "scripts", "compute_workspace_client.py")


class ComputeWorkspaceClient(unittest.TestCase):
    def test_docs_quote_the_client(self):
        with open(CLIENT) as script, open(os.path.join(PACKAGE, "docs", "ros.md")) as docs:
            quoted = "```python\n" + script.read() + "```\n" in docs.read()
        self.assertTrue(quoted, "docs/ros.md does not quote scripts/compute_workspace_client.py as it is")

    def test_client_prints_feedback_and_the_result(self):
        rospy.wait_for_service("/compute_workspace", timeout=60.0)
        run = subprocess.run(["rosrun", "maximal_workspace", "compute_workspace_client.py", "0.05"],
                             capture_output=True, text=True, timeout=90.0)
        said = f"exit {run.returncode}\nstdout:\n{run.stdout}\nstderr:\n{run.stderr}"
        self.assertEqual(run.returncode, 0, said)
        feedback = re.findall(r"^(\w+): (\d+) %, [\d.]+ s, -?[\d.]+ s left$", run.stdout, re.MULTILINE)
        self.assertGreaterEqual(len(feedback), 2, "no feedback before the result: " + said)
        self.assertEqual(feedback[-1], ("done", "100"), said)
        self.assertRegex(run.stdout, r"\ncomputed in [\d.e-]+ s, stored in [\d.e-]+ s: workspace 0\.\d+ m\^3\n", said)
        self.assertRegex(run.stdout, r"\nassembly mode \+1: maximal 0\.\d+ m\^3, \d+ regions, \d+ transitions\n", said)
        self.assertRegex(run.stdout, r"\nsummary: /tmp/mow_client_rostest_cache\S*/summary\.json\n", said)


if __name__ == "__main__":
    rospy.init_node("test_compute_workspace_client")
    run_removing_server_cache("compute_workspace_client", ComputeWorkspaceClient)
