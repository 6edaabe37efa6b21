#pragma once
// `mow sweep` under mpirun (docs/sweep.md): the study's designs spread over the ranks of
// an MPI job. Built only with MPI (MOW_WITH_MPI); the thread pool (runStudy) is the other
// scheduler, behind the same options and report.

#include <optional>

#include "maximal_workspace/sweep/sweep_runner.h"

namespace maximal_workspace::cli {

// Every rank calls it with the study it read; MPI is initialised and finalised inside.
// Rank 0 keeps the results file: it skips the designs recorded there, hands the others
// one at a time to whichever rank asks next (so costly designs do not hold up cheap ones),
// and appends each row sent back. The other ranks analyse one design at a time on
// `options.jobs` threads. Rank 0 returns the report, the others nothing. Throws as
// runStudy does, on rank 0 only (a worker's Ctrl-C or error is sent to rank 0); InputError
// on every rank when the ranks read different studies.
std::optional<SweepReport> runStudyOnRanks(const Study& study, const SweepOptions& options);

}  // namespace maximal_workspace::cli
