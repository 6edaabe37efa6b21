// workspace_worker: computes one cache entry for workspace_server (entry_computation.h),
// in a process of its own. Started by the server with its process id as the argument;
// ends with the server.

#include <sys/prctl.h>
#include <sys/resource.h>
#include <unistd.h>

#include <csignal>
#include <cstdlib>
#include <iostream>
#include <string>

#include "maximal_workspace/io/entry_computation.h"

int main(int argc, char** argv) {
  // A worker outliving a killed server would compute for nobody, into a staging directory
  // the next server removes.
  prctl(PR_SET_PDEATHSIG, SIGKILL);
  // Ctrl-C in a terminal reaches the whole process group: the server, which decides, stops
  // its workers itself (at once, SIGKILL) when it shuts down.
  std::signal(SIGINT, SIG_IGN);
  // Below the server's threads: a cached answer gets a core at once, and nothing of the
  // server waits on a lock a worker holds (another process), so no priority inversion.
  setpriority(PRIO_PROCESS, 0, getpriority(PRIO_PROCESS, 0) + 10);
  if (argc != 2 || std::to_string(getppid()) != argv[1]) {
    std::cerr << "workspace_worker: started by workspace_server only (its process id as the argument)\n";
    return 2;
  }
  return maximal_workspace::runWorkspaceWorker(std::cin, std::cout);
}
