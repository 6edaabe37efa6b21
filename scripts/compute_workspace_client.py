#!/usr/bin/python3
"""A Python client of workspace_server's compute_workspace_action: sends a goal, prints the
feedback as it comes and the result. rosrun maximal_workspace compute_workspace_client.py [STEP]"""
import sys

import actionlib
import rospy
from actionlib_msgs.msg import GoalStatus
from maximal_workspace.msg import ComputeWorkspaceAction, ComputeWorkspaceGoal


def on_feedback(feedback):
    p = feedback.progress
    print(f"{p.stage}: {100 * p.fraction:.0f} %, {p.elapsed:.1f} s, {p.remaining:.1f} s left", flush=True)


def main():
    rospy.init_node("compute_workspace_client", anonymous=True)
    args = rospy.myargv()
    step = float(args[1]) if len(args) > 1 else 0.0  # 0: the server's default_step
    client = actionlib.SimpleActionClient("compute_workspace_action", ComputeWorkspaceAction)
    if not client.wait_for_server(rospy.Duration(30.0)):
        sys.exit("no compute_workspace_action: start workspace_server (roslaunch maximal_workspace workspace.launch)")
    client.send_goal(ComputeWorkspaceGoal(step=step), feedback_cb=on_feedback)
    client.wait_for_result()
    result = client.get_result()
    if client.get_state() != GoalStatus.SUCCEEDED:
        sys.exit(f"goal not done: {client.get_goal_status_text()}")
    print(f"{result.message}: workspace {result.workspace_volume:.4f} {result.volume_unit}")
    for am in result.assembly_modes:
        print(f"assembly mode {am.sign:+d}: maximal {am.maximal_volume:.4f} {result.volume_unit}, "
              f"{am.regions} regions, {am.transitions} transitions")
    print(f"summary: {result.summary_file}")


if __name__ == "__main__":
    main()
