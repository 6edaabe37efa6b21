#!/usr/bin/python3
"""Latency of the nodes from persistent clients: /compute_workspace, the first call
(which may compute) then N calls of the same request (from the cache); and, when
/plan_path is up, M plans at the same step (trajectory and verification included), the
first of which loads the workspace. Prints medians and ranges. Run with the nodes up
(roslaunch maximal_workspace planner.launch step:=STEP).
Usage: scripts/bench_service.py [step] [calls] [plans]"""
import statistics
import sys
import time

import rospy
from geometry_msgs.msg import Pose
from maximal_workspace.srv import ComputeWorkspace, ComputeWorkspaceRequest, PlanPath, PlanPathRequest

step = float(sys.argv[1]) if len(sys.argv) > 1 else 0.01
calls = int(sys.argv[2]) if len(sys.argv) > 2 else 50
plans = int(sys.argv[3]) if len(sys.argv) > 3 else 20


def timed(call):
    start = time.perf_counter()
    result = call()
    return result, 1000 * (time.perf_counter() - start)


def summary(name, times):
    print(f"step {step}: {len(times)} {name}: median {statistics.median(times):.1f} ms, "
          f"min {min(times):.1f} ms, max {max(times):.1f} ms")


def pose(x, y, z):
    p = Pose()
    p.position.x, p.position.y, p.position.z = x, y, z
    p.orientation.w = 1.0
    return p


rospy.init_node("bench_service", anonymous=True)
rospy.wait_for_service("compute_workspace", timeout=30)
service = rospy.ServiceProxy("compute_workspace", ComputeWorkspace, persistent=True)
request = ComputeWorkspaceRequest(step=step)
first, ms = timed(lambda: service(request))
print(f"step {step}: first call {ms:.1f} ms ({first.message})")
times = []
for _ in range(calls):
    response, ms = timed(lambda: service(request))
    times.append(ms)
    assert response.success and response.from_cache, response.message
summary("cached calls", times)

try:
    rospy.wait_for_service("plan_path", timeout=5)
except rospy.ROSException:
    sys.exit(0)
planner = rospy.ServiceProxy("plan_path", PlanPath, persistent=True)
# From the reference pose (its working mode known): the chapter's Fig. 14 goal, through
# transitions, and a goal in the start's own region (docs/planner.md).
goals = [(pose(0.15, 0.15, 0.75), pose(0.775, 0.455, 0.075)), (pose(0.15, 0.15, 0.75), pose(0.25, 0.2, 0.65))]
times = []
for k in range(plans + 1):
    start, goal = goals[k % len(goals)]
    plan, ms = timed(lambda: planner(PlanPathRequest(step=step, start=start, goal=goal)))
    assert plan.success and plan.verified, plan.message
    if k == 0:
        print(f"step {step}: first plan {ms:.1f} ms, the workspace loaded ({plan.message})")
    else:
        times.append(ms)
summary("plans with trajectory and verification", times)
