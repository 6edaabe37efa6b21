#include "maximal_workspace/workspace/thread_priority.h"

#include <algorithm>
#include <cerrno>

#include <sys/resource.h>
#include <sys/syscall.h>
#include <unistd.h>

namespace maximal_workspace {

void lowerThisThreadsPriority() {
  // On Linux, PRIO_PROCESS with a thread id sets that thread's nice value alone.
  const auto thread = static_cast<id_t>(::syscall(SYS_gettid));
  errno = 0;
  const int nice = ::getpriority(PRIO_PROCESS, thread);
  if (errno == 0) ::setpriority(PRIO_PROCESS, thread, std::min(nice + 10, 19));
}

}  // namespace maximal_workspace
