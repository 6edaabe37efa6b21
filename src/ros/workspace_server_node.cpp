// workspace_server: see workspace_server.h.

#include <csignal>

#include <malloc.h>

#include <ros/ros.h>

#include "workspace_server.h"

int main(int argc, char** argv) {
  // Heaps grow in 64 MiB steps and keep up to 256 MiB free: growing or trimming one takes
  // the process's memory-map lock, which freeing an analysis (the publisher's, now that
  // computations run in workers) holds for tens of milliseconds, and a cached answer that
  // grew its heap waited behind it (perf: mprotect in rwsem_down_write_slowpath;
  // docs/reliability.md).
  mallopt(M_TOP_PAD, 64 << 20);
  mallopt(M_TRIM_THRESHOLD, 256 << 20);
  ros::init(argc, argv, "workspace_server");
  // SIGTERM (a process manager's stop) as roscpp takes SIGINT: shut down, which cancels a
  // running computation, instead of dying with its files half-written.
  std::signal(SIGTERM, [](int) { ros::requestShutdown(); });
  ros::NodeHandle node;
  ros::NodeHandle private_node("~");
  maximal_workspace::WorkspaceServer server(node, private_node);
  ros::AsyncSpinner spinner(server.callbackThreads());
  spinner.start();
  ros::waitForShutdown();
  return 0;
}
