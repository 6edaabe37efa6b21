// workspace_server: see workspace_server.h.

#include <csignal>

#include <ros/ros.h>

#include "workspace_server.h"

int main(int argc, char** argv) {
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
