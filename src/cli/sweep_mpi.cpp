#include "sweep_mpi.h"

#include <mpi.h>

#include <chrono>
#include <cstdint>
#include <cstring>
#include <exception>
#include <functional>
#include <memory>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

#include "maximal_workspace/model/input_error.h"

namespace maximal_workspace::cli {

namespace {

// What rank 0 and a worker say to each other, told apart by the message's tag.
enum Tag : int {
  kReady = 1,  // worker -> 0: its first request for a design
  kRow,        // worker -> 0: a finished design (a DesignResult, serialised), and a request for the next
  kCancelled,  // worker -> 0: interrupted mid-design; it stops
  kFailed,     // worker -> 0: an internal error (its message); it stops
  kDesign,     // 0 -> worker: the index of the design to analyse
  kStop,       // 0 -> worker: nothing more to do
};

// How often rank 0 looks for Ctrl-C while it waits for rows: an idle rank 0 must not take
// a core from the workers (MPI's blocking receive spins).
constexpr auto kPollInterval = std::chrono::milliseconds(2);

class MpiSession {
 public:
  MpiSession() {
    int provided = 0;
    // Only this thread calls MPI; a design's analysis may run threads of its own.
    MPI_Init_thread(nullptr, nullptr, MPI_THREAD_FUNNELED, &provided);
    MPI_Comm_rank(MPI_COMM_WORLD, &rank_);
    MPI_Comm_size(MPI_COMM_WORLD, &size_);
  }
  ~MpiSession() { MPI_Finalize(); }
  MpiSession(const MpiSession&) = delete;
  MpiSession& operator=(const MpiSession&) = delete;

  int rank() const { return rank_; }
  int size() const { return size_; }

 private:
  int rank_ = 0, size_ = 1;
};

void send(int rank, Tag tag, const std::string& bytes) {
  MPI_Send(bytes.data(), static_cast<int>(bytes.size()), MPI_BYTE, rank, tag, MPI_COMM_WORLD);
}

// Rows stay exact: the doubles travel as their bytes (the ranks of one job share a byte order).
std::string serialised(const DesignResult& result) {
  std::string bytes;
  const auto put = [&bytes](const void* data, std::size_t size) { bytes.append(static_cast<const char*>(data), size); };
  const std::uint64_t design = result.design, figures = result.figures.size();
  const std::int32_t status = static_cast<std::int32_t>(result.status);
  put(&design, sizeof design);
  put(&status, sizeof status);
  put(&figures, sizeof figures);
  put(result.figures.data(), figures * sizeof(double));
  return bytes + result.reason;
}

DesignResult deserialised(const std::string& bytes, int rank) {
  std::size_t at = 0;
  const auto take = [&](void* data, std::size_t size) {
    if (bytes.size() - at < size) throw std::runtime_error("rank " + std::to_string(rank) + " sent a truncated row");
    std::memcpy(data, bytes.data() + at, size);
    at += size;
  };
  std::uint64_t design = 0, figures = 0;
  std::int32_t status = 0;
  take(&design, sizeof design);
  take(&status, sizeof status);
  take(&figures, sizeof figures);
  if (status < 0 || status >= kDesignStatusCount || figures > bytes.size() / sizeof(double)) {
    throw std::runtime_error("rank " + std::to_string(rank) + " sent a malformed row");
  }
  DesignResult result;
  result.design = design;
  result.status = static_cast<DesignStatus>(status);
  result.figures.resize(figures);
  take(result.figures.data(), figures * sizeof(double));
  result.reason = bytes.substr(at);
  return result;
}

struct Message {
  int source = 0;
  int tag = 0;
  std::string bytes;
};

// The next message from any worker; `idle` is called between looks while none has come.
Message receive(const std::function<void()>& idle) {
  MPI_Status status{};
  for (int arrived = 0;;) {
    MPI_Iprobe(MPI_ANY_SOURCE, MPI_ANY_TAG, MPI_COMM_WORLD, &arrived, &status);
    if (arrived) break;
    idle();
    std::this_thread::sleep_for(kPollInterval);
  }
  int size = 0;
  MPI_Get_count(&status, MPI_BYTE, &size);
  Message message{status.MPI_SOURCE, status.MPI_TAG, std::string(static_cast<std::size_t>(size), '\0')};
  MPI_Recv(message.bytes.data(), size, MPI_BYTE, status.MPI_SOURCE, status.MPI_TAG, MPI_COMM_WORLD, MPI_STATUS_IGNORE);
  return message;
}

// Every rank must run the same study (the same study and robot files on every machine),
// or rows of another study would be mixed in.
void checkSameStudy(const Study& study, const MpiSession& mpi) {
  constexpr int kWidth = 32;  // a fingerprint is 16 hex digits
  char own[kWidth] = {};
  std::strncpy(own, study.fingerprint().c_str(), kWidth - 1);
  std::vector<char> all(static_cast<std::size_t>(kWidth) * static_cast<std::size_t>(mpi.size()));
  MPI_Allgather(own, kWidth, MPI_CHAR, all.data(), kWidth, MPI_CHAR, MPI_COMM_WORLD);
  for (int rank = 1; rank < mpi.size(); ++rank) {
    const std::string theirs(&all[static_cast<std::size_t>(rank) * kWidth]);
    if (theirs != std::string(all.data())) {
      throw InputError(study.path() + ": rank " + std::to_string(rank) + " read another study (study " + theirs +
                       "; rank 0 read study " + std::string(all.data()) +
                       "): every rank needs the same study and robot files");
    }
  }
}

// Rank 0: the results file, and the designs handed out as the workers ask. An error (a
// results file refused, a full disk) or Ctrl-C stops the handing out; every worker is then
// told to stop at its next request before this returns, so that none waits forever.
SweepReport lead(const Study& study, const SweepOptions& options, int workers) {
  const auto started = std::chrono::steady_clock::now();
  std::exception_ptr error;
  std::unique_ptr<ResultsFile> results;
  std::vector<std::size_t> to_run;
  try {
    results = std::make_unique<ResultsFile>(options.out, study, options.force);
    to_run = designsToRun(study, *results);
    DesignRunOptions preparing;
    preparing.cancelled = options.cancelled;
    prepareUntilOneFits(study, to_run, preparing, *results);  // the prepared designs go to the workers by index
  } catch (...) {
    error = std::current_exception();
  }
  const std::size_t recorded_before = study.designCount() - to_run.size();
  bool cancelled = false;
  const auto lookForCtrlC = [&] { cancelled = cancelled || (options.cancelled && options.cancelled()); };
  std::size_t next = 0, finished = 0;
  for (int active = workers; active > 0;) {
    const Message message = receive(lookForCtrlC);
    if (message.tag == kCancelled || message.tag == kFailed) {
      if (message.tag == kCancelled) cancelled = true;
      if (message.tag == kFailed && !error) {
        error = std::make_exception_ptr(std::runtime_error("rank " + std::to_string(message.source) + ": " + message.bytes));
      }
      --active;
      continue;
    }
    if (message.tag == kRow && !error) {
      try {
        const DesignResult result = deserialised(message.bytes, message.source);
        results->append(result);
        if (options.progress) options.progress(SweepProgress{++finished, to_run.size(), &result});
      } catch (...) {
        error = std::current_exception();
      }
    }
    lookForCtrlC();
    if (!error && !cancelled && next < to_run.size()) {
      const std::uint64_t design = to_run[next++];
      MPI_Send(&design, 1, MPI_UINT64_T, message.source, kDesign, MPI_COMM_WORLD);
    } else {
      MPI_Send(nullptr, 0, MPI_UINT64_T, message.source, kStop, MPI_COMM_WORLD);
      --active;
    }
  }
  if (error) std::rethrow_exception(error);
  if (cancelled && finished < to_run.size()) throw Cancelled();
  return sweepReport(study, *results, recorded_before, started);
}

// A worker: designs from rank 0 until it says stop. Ctrl-C ends the design in flight (as
// in the thread mode), and an internal error the worker; either is told to rank 0, which
// hands out no more and ends with the error or exit code 130. The worker itself ends
// quietly: a rank ending in failure makes mpirun kill the others, rank 0 among them,
// before it has heard from every worker.
void work(const Study& study, const SweepOptions& options) {
  DesignRunOptions run;
  run.threads = options.jobs;
  run.cancelled = options.cancelled;
  send(0, kReady, "");
  for (;;) {
    std::uint64_t design = 0;
    MPI_Status status{};
    MPI_Recv(&design, 1, MPI_UINT64_T, 0, MPI_ANY_TAG, MPI_COMM_WORLD, &status);
    if (status.MPI_TAG == kStop) return;
    DesignResult result;
    try {
      result = runDesign(study, static_cast<std::size_t>(design), run);
    } catch (const Cancelled&) {
      send(0, kCancelled, "");
      return;
    } catch (const std::exception& failure) {
      send(0, kFailed, failure.what());
      return;
    }
    send(0, kRow, serialised(result));
  }
}

}  // namespace

std::optional<SweepReport> runStudyOnRanks(const Study& study, const SweepOptions& options) {
  MpiSession mpi;
  checkSameStudy(study, mpi);
  if (mpi.size() == 1) return runStudy(study, options);  // a singleton: no one to hand designs to
  if (mpi.rank() == 0) return lead(study, options, mpi.size() - 1);
  work(study, options);
  return std::nullopt;
}

}  // namespace maximal_workspace::cli
