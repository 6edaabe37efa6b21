#pragma once
// Long work that must not slow a process's quick answers: a server's computations and the
// sampling of their results for display run below its callbacks.

namespace maximal_workspace {

// Lowers the calling thread's scheduling priority by 10 (nice, at most 19); threads it
// starts inherit it. Raising it back needs privileges, so call it on a thread of its own.
// A refusal leaves the priority as it was.
void lowerThisThreadsPriority();

}  // namespace maximal_workspace
