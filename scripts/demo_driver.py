#!/usr/bin/python3
"""The demo's script (launch/demo.launch): computes the default workspace, plans the
chapter's Fig. 14-like path from the reference configuration, plays it back on the robot
display, and prints what it got and where the files are. With ~exit_when_done it then
stops (and, being required, the whole demo with it): the headless demo."""
import sys

import rospy
from geometry_msgs.msg import Pose
from maximal_workspace.srv import ComputeWorkspace, ComputeWorkspaceRequest, PlanPath, PlanPathRequest
from std_srvs.srv import Trigger


def pose(xyz):
    p = Pose()
    p.position.x, p.position.y, p.position.z = xyz
    p.orientation.w = 1.0
    return p


def count(n, noun):
    """'1 transition', '2 transitions'."""
    return f"{n} {noun}" + ("" if n == 1 else "s")


def service(name, kind, timeout):
    rospy.wait_for_service(name, timeout=timeout)
    return rospy.ServiceProxy(name, kind)


def main():
    rospy.init_node("demo_driver")
    step = rospy.get_param("~step", 0.01)
    # config/demo/ROBOT.yaml, loaded by demo.launch
    start = rospy.get_param("~start")
    goal = rospy.get_param("~goal")
    exit_when_done = rospy.get_param("~exit_when_done", False)

    workspace = service("compute_workspace", ComputeWorkspace, 120)(ComputeWorkspaceRequest(step=step))
    if not workspace.success:
        rospy.logfatal("demo: no workspace: %s", workspace.message)
        sys.exit(1)
    signs = "exact" if workspace.margin == 0 else f"margin {workspace.margin:g}"
    print(f"\n== workspace of {rospy.get_param('~robot', 'the robot')} at step {step} m, {signs} ({workspace.message})")
    print(f"workspace volume {workspace.workspace_volume:.4f} {workspace.volume_unit}")
    for am in workspace.assembly_modes:
        share = lambda volume: 100.0 * volume / workspace.workspace_volume
        print(f"assembly mode {'+' if am.sign > 0 else '-'}: maximal {share(am.maximal_volume):.1f} %, "
              f"traditional {share(am.traditional_volume):.1f} %, reachable from the start "
              f"{share(am.reachable_volume):.1f} %, {count(am.regions, 'region')}, {count(am.transitions, 'transition')}")
    print(f"summary: {workspace.summary_file}")
    print("octrees: " + " ".join(workspace.octree_files))

    plan = service("plan_path", PlanPath, 60)(PlanPathRequest(start=pose(start), goal=pose(goal), step=step))
    print(f"\n== path from {start} to {goal}")
    if not plan.success:
        rospy.logfatal("demo: no plan: %s", plan.message)
        sys.exit(1)
    print(f"{plan.message}; starts in {plan.working_modes[0]}, ends in {plan.working_modes[-1]}")
    at = plan.min_measure_at
    print(f"min |measure| {plan.min_measure:.3g} at ({at.x:.3f}, {at.y:.3f}, {at.z:.3f})")
    for transition in plan.transitions:
        p = transition.point
        print(f"  {transition.label} ({transition.from_working_mode} -> {transition.to_working_mode}) "
              f"at ({p.x:.3f}, {p.y:.3f}, {p.z:.3f})")
    print(f"verification: {plan.verification}")

    # The robot display gets the plan on its latched topic; give it a moment, then play.
    rospy.sleep(1.0)
    played = service("robot_pose_publisher/play", Trigger, 30)()
    print(f"\n== playback: {played.message}")
    if exit_when_done:
        duration = plan.trajectory.points[-1].time_from_start.to_sec() / rospy.get_param("~playback_speed", 1.0)
        rospy.sleep(duration + 0.5)
        print("demo done: roslaunch stops the other nodes now (its 'REQUIRED process has died' is this normal end)")
        rospy.signal_shutdown("demo done")
        return
    rospy.spin()


if __name__ == "__main__":
    main()
