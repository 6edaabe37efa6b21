#!/usr/bin/python3
"""Latency of /compute_workspace from a persistent client: the first call (which may
compute), then N calls of the same request (from the cache). Prints the median and the
range. Run with a workspace_server up (roslaunch maximal_workspace workspace.launch).
Usage: scripts/bench_service.py [step] [calls]"""
import statistics
import sys
import time

import rospy
from maximal_workspace.srv import ComputeWorkspace, ComputeWorkspaceRequest

step = float(sys.argv[1]) if len(sys.argv) > 1 else 0.01
calls = int(sys.argv[2]) if len(sys.argv) > 2 else 50
rospy.init_node("bench_service", anonymous=True)
rospy.wait_for_service("compute_workspace", timeout=30)
service = rospy.ServiceProxy("compute_workspace", ComputeWorkspace, persistent=True)
request = ComputeWorkspaceRequest(step=step)
start = time.perf_counter()
first = service(request)
print(f"step {step}: first call {1000 * (time.perf_counter() - start):.1f} ms ({first.message})")
times = []
for _ in range(calls):
    start = time.perf_counter()
    response = service(request)
    times.append(1000 * (time.perf_counter() - start))
    assert response.success and response.from_cache, response.message
print(f"step {step}: {calls} cached calls: median {statistics.median(times):.1f} ms, "
      f"min {min(times):.1f} ms, max {max(times):.1f} ms")
