// Both sides of the worker protocol (entry_computation.h): the job goes to the worker's
// standard input as one JSON document; the worker answers with lines on its standard
// output:
//   analysis <fraction> <poses evaluated> <cells inside> <stage>
//   storing <fraction>
//   done <seconds> <storing seconds> <poses evaluated> <voxels> <peak resident bytes>   (exit 0)
//   refused <message>                              (exit 2: an InputError)
//   failed <message>                               (exit 1)
// Its standard input and output are one end of a socket pair, so that the server writes
// with MSG_NOSIGNAL (a worker that died is an error, not a SIGPIPE) and polls for lines.

#include <poll.h>
#include <signal.h>
#include <spawn.h>
#include <sys/socket.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstring>
#include <fstream>
#include <sstream>
#include <thread>

#include <nlohmann/json.hpp>

#include "maximal_workspace/io/checksum.h"
#include "maximal_workspace/io/entry_computation.h"
#include "maximal_workspace/io/text_file.h"
#include "maximal_workspace/model/input_error.h"
#include "maximal_workspace/model/robot_file.h"
#include "maximal_workspace/model/vector_text.h"
#include "maximal_workspace/workspace/cancellation.h"

extern char** environ;

namespace maximal_workspace {

namespace {

using nlohmann::json;

constexpr int kJobFormat = 1;
// A job is a path, a grid and working-mode names: kilobytes. Worker lines are shorter than
// a refusal naming what is wrong (the loader clips what it quotes).
constexpr std::size_t kMaxJobBytes = std::size_t{1} << 20;
constexpr std::size_t kMaxWorkerLineBytes = std::size_t{1} << 16;

json jobJson(const ResolvedWorkspaceRequest& request, const RobotSource& source, const std::string& staging) {
  const GridSpec& spec = request.spec;
  json grid;
  grid["variables"] = json::array();
  for (OutputVariable variable : spec.variables) grid["variables"].push_back(outputVariableName(variable));
  grid["steps"] = spec.steps;
  std::vector<double> start;
  for (int v = 0; v < kOutputVariableCount; ++v) start.push_back(spec.start.value(static_cast<OutputVariable>(v)));
  grid["start"] = start;
  grid["bounds"] = spec.bounds;
  grid["tilt_torsion"] = spec.orientation == OrientationCoordinates::TiltTorsion;
  const AnalysisOptions& options = request.options;
  const json analysis = {{"margin", options.margin},
                         {"debris_voxels", options.debris.min_voxels},
                         {"debris_fraction", options.debris.min_fraction},
                         {"uncoupled", options.uncoupled},
                         {"working_modes", options.working_modes},
                         {"start_mode", options.start_mode},
                         {"transition_tolerance", options.transition_tolerance},
                         {"threads", options.threads},
                         {"memory_budget", options.memory_budget},
                         {"conditioning", options.conditioning ? json{{"threshold", options.conditioning->threshold},
                                                                      {"evaluations", options.conditioning->evaluations}}
                                                               : json()}};
  return {{"format", kJobFormat}, {"robot_file", source.path}, {"robot_hash", source.hash}, {"key", request.key},
          {"staging", staging},   {"grid", grid},              {"options", analysis}};
}

// The request a job names, resolved again from the robot file as it is now: the same key
// or an InputError.
struct Job {
  ResolvedWorkspaceRequest request;
  RobotModel model;
  RobotSource source;
  std::string staging;
};

Job readJob(std::istream& in) {
  std::string text;
  text.resize(kMaxJobBytes + 1);
  in.read(text.data(), static_cast<std::streamsize>(text.size()));
  text.resize(static_cast<std::size_t>(in.gcount()));
  if (text.size() > kMaxJobBytes) throw InputError("the job is over " + byteText(kMaxJobBytes));
  const json job = json::parse(text, nullptr, false);
  if (job.is_discarded() || !job.is_object()) throw InputError("the job is not a JSON object");
  try {
    if (job.at("format").get<int>() != kJobFormat) throw InputError("the job is of another format");
    Job read;
    read.source.path = job.at("robot_file").get<std::string>();
    const std::string robot_text = readTextFile(read.source.path, "robot file");
    read.source.hash = hex64(fnv1a64(robot_text));
    if (read.source.hash != job.at("robot_hash").get<std::string>()) {
      throw InputError(read.source.path + " changed while the request waited; ask again");
    }
    read.model = parseRobotFile(robot_text, read.source.path);
    const json& grid = job.at("grid");
    GridSpec spec;
    for (const json& name : grid.at("variables")) {
      const std::optional<OutputVariable> variable = parseOutputVariable(name.get<std::string>());
      if (!variable) throw InputError("the job names an unknown variable");
      spec.variables.push_back(*variable);
    }
    spec.steps = grid.at("steps").get<std::vector<double>>();
    const auto start = grid.at("start").get<std::vector<double>>();
    if (start.size() != kOutputVariableCount) throw InputError("the job's start is not a pose");
    for (int v = 0; v < kOutputVariableCount; ++v) spec.start.setValue(static_cast<OutputVariable>(v), start[v]);
    spec.bounds = grid.at("bounds").get<std::vector<std::array<double, 2>>>();
    // Absent: Euler angles, as before orientation sets.
    if (grid.value("tilt_torsion", false)) spec.orientation = OrientationCoordinates::TiltTorsion;
    const json& analysis = job.at("options");
    AnalysisOptions options;
    options.margin = analysis.at("margin").get<double>();
    options.debris.min_voxels = analysis.at("debris_voxels").get<std::uint64_t>();
    options.debris.min_fraction = analysis.at("debris_fraction").get<double>();
    options.uncoupled = analysis.at("uncoupled").get<bool>();
    options.working_modes = analysis.at("working_modes").get<std::vector<std::string>>();
    options.transition_tolerance = analysis.at("transition_tolerance").get<double>();
    options.threads = analysis.at("threads").get<int>();
    // The server holds threads to the machine's; a job over them would only start threads that wait.
    const int machine = static_cast<int>(std::max(1u, std::thread::hardware_concurrency()));
    if (options.threads < 0 || options.threads > machine) {
      throw InputError("the job asks for " + std::to_string(options.threads) + " threads, not 0 to the machine's " +
                       std::to_string(machine));
    }
    options.memory_budget = analysis.at("memory_budget").get<std::uint64_t>();
    if (const json conditioning = analysis.value("conditioning", json()); !conditioning.is_null()) {
      options.conditioning = ConditioningRequest{conditioning.at("threshold").get<double>(),
                                                 conditioning.at("evaluations").get<std::uint64_t>()};
    }
    const std::string start_mode = analysis.at("start_mode").get<std::string>();
    read.request = resolveAnalysis(read.model, robot_text, spec, options, start_mode);
    if (read.request.key != job.at("key").get<std::string>()) {
      throw InputError("the job resolves to cache key " + read.request.key + ", not " + job.at("key").get<std::string>());
    }
    read.staging = job.at("staging").get<std::string>();
    return read;
  } catch (const json::exception& error) {
    throw InputError(std::string("the job is malformed: ") + error.what());
  }
}

// This process's peak resident memory (VmHWM). Not getrusage's: the kernel carries the
// maximum of the memory map a process had before exec, which under posix_spawn is the
// server's.
std::uint64_t peakResidentBytes() {
  std::ifstream status("/proc/self/status");
  for (std::string line; std::getline(status, line);) {
    if (line.rfind("VmHWM:", 0) == 0) return std::stoull(line.substr(6)) * 1024;
  }
  return 0;
}

// One line of the protocol: no line break inside.
std::string oneLine(std::string text) {
  for (char& c : text) {
    if (c == '\n' || c == '\r') c = ' ';
  }
  return text;
}

std::string signalText(int signal) {
  const char* name = strsignal(signal);
  return std::to_string(signal) + " (" + (name != nullptr ? name : "unknown") + ")";
}

// A file descriptor closed when it goes.
class Descriptor {
 public:
  explicit Descriptor(int fd = -1) : fd_(fd) {}
  Descriptor(const Descriptor&) = delete;
  Descriptor& operator=(const Descriptor&) = delete;
  ~Descriptor() { reset(); }
  int get() const { return fd_; }
  void reset() {
    if (fd_ >= 0) ::close(fd_);
    fd_ = -1;
  }

 private:
  int fd_;
};

// The worker, killed and reaped when it goes unless it was waited for: an exception (a
// cancellation included) never leaves it running or a zombie.
class WorkerChild {
 public:
  explicit WorkerChild(pid_t pid) : pid_(pid) {}
  WorkerChild(const WorkerChild&) = delete;
  WorkerChild& operator=(const WorkerChild&) = delete;
  ~WorkerChild() {
    if (waited_) return;
    ::kill(pid_, SIGKILL);
    int status = 0;
    while (::waitpid(pid_, &status, 0) < 0 && errno == EINTR) {
    }
  }
  // Its exit status.
  int wait() {
    int status = 0;
    while (::waitpid(pid_, &status, 0) < 0) {
      if (errno != EINTR) throw std::runtime_error(std::string("cannot wait for the workspace worker: ") + std::strerror(errno));
    }
    waited_ = true;
    return status;
  }

 private:
  pid_t pid_;
  bool waited_ = false;
};

// A worker that ended before reading its job (EPIPE, ECONNRESET) is not an error here: its exit
// status, read next, says why, whichever of the two raced ahead.
void sendAll(int fd, const std::string& bytes) {
  std::size_t sent = 0;
  while (sent < bytes.size()) {
    const ssize_t n = ::send(fd, bytes.data() + sent, bytes.size() - sent, MSG_NOSIGNAL);
    if (n < 0 && errno == EINTR) continue;
    if (n < 0 && (errno == EPIPE || errno == ECONNRESET)) return;
    if (n < 0) throw std::runtime_error(std::string("cannot send the job to the workspace worker: ") + std::strerror(errno));
    sent += static_cast<std::size_t>(n);
  }
}

// One line the worker wrote: progress goes to the request's and `storing`'s callbacks; its
// last "done", "refused" or "failed" line to `ending` (a "done" line's figures to `computed`).
void readWorkerLine(const std::string& line, const ResolvedWorkspaceRequest& request,
                    const std::function<void(double)>& storing, ComputedEntry& computed, std::string& ending) {
  std::istringstream fields(line);
  std::string kind;
  fields >> kind;
  if (kind == "analysis") {
    AnalysisProgress progress;
    std::string stage;
    fields >> progress.fraction >> progress.evaluated >> progress.inside >> std::ws;
    std::getline(fields, stage);
    progress.stage = stage.c_str();
    if (request.options.progress) request.options.progress(progress);
  } else if (kind == "storing") {
    double fraction = 0.0;
    fields >> fraction;
    if (storing) storing(fraction);
  } else if (kind == "done") {
    fields >> computed.seconds >> computed.storing_seconds >> computed.poses_evaluated >> computed.voxels >>
        computed.peak_bytes;
    ending = line;
  } else {
    ending = line;
  }
}

}  // namespace

WorkerProcessComputation::WorkerProcessComputation(std::string executable) : executable_(std::move(executable)) {}

ComputedEntry WorkerProcessComputation::compute(const ResolvedWorkspaceRequest& request, const RobotModel&,
                                                const RobotSource& source, const std::string& staging,
                                                const std::function<void(double)>& storing) const {
  int ends[2];
  if (::socketpair(AF_UNIX, SOCK_STREAM | SOCK_CLOEXEC, 0, ends) != 0) {
    throw std::runtime_error(std::string("cannot connect to a workspace worker: ") + std::strerror(errno));
  }
  Descriptor server_end(ends[0]), worker_end(ends[1]);
  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  posix_spawn_file_actions_adddup2(&actions, worker_end.get(), STDIN_FILENO);
  posix_spawn_file_actions_adddup2(&actions, worker_end.get(), STDOUT_FILENO);
  // Nothing else of the caller's (a node's sockets): a connection it closes stays closed.
  posix_spawn_file_actions_addclosefrom_np(&actions, STDERR_FILENO + 1);
  const std::string parent = std::to_string(::getpid());
  char* argv[] = {const_cast<char*>(executable_.c_str()), const_cast<char*>(parent.c_str()), nullptr};
  pid_t pid = 0;
  // posix_spawn shares the memory map until exec (no copy of a large process's page tables).
  const int error = ::posix_spawn(&pid, executable_.c_str(), &actions, nullptr, argv, environ);
  posix_spawn_file_actions_destroy(&actions);
  worker_end.reset();
  if (error != 0) {
    throw std::runtime_error("cannot start the workspace worker " + executable_ + ": " + std::strerror(error));
  }
  WorkerChild worker(pid);
  sendAll(server_end.get(), jobJson(request, source, staging).dump());
  ::shutdown(server_end.get(), SHUT_WR);

  ComputedEntry computed;
  std::string ending;  // the worker's last "done", "refused" or "failed" line
  std::string pending;
  char buffer[4096];
  while (true) {
    throwIfCancelled(request.options.cancelled);
    pollfd ready{server_end.get(), POLLIN, 0};
    const int polled = ::poll(&ready, 1, 100);
    if (polled < 0 && errno != EINTR) {
      throw std::runtime_error(std::string("cannot read the workspace worker: ") + std::strerror(errno));
    }
    if (polled <= 0) continue;
    const ssize_t n = ::recv(server_end.get(), buffer, sizeof buffer, 0);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) break;  // it ended (or its end broke): its status says how
    pending.append(buffer, static_cast<std::size_t>(n));
    for (std::size_t end; (end = pending.find('\n')) != std::string::npos;) {
      readWorkerLine(pending.substr(0, end), request, storing, computed, ending);
      pending.erase(0, end + 1);
    }
    if (pending.size() > kMaxWorkerLineBytes) throw std::runtime_error("the workspace worker wrote a line too long");
  }
  const int status = worker.wait();
  const std::string said = ending.substr(std::min(ending.size(), ending.find(' ') + 1));
  if (WIFEXITED(status) && WEXITSTATUS(status) == 0 && ending.rfind("done ", 0) == 0) return computed;
  if (WIFEXITED(status) && WEXITSTATUS(status) == 2 && ending.rfind("refused ", 0) == 0) throw InputError(said);
  if (WIFSIGNALED(status)) {
    throw std::runtime_error("the workspace worker was ended by signal " + signalText(WTERMSIG(status)) +
                             (WTERMSIG(status) == SIGKILL ? ": out of memory?" : ""));
  }
  throw std::runtime_error("the workspace worker failed (exit " + std::to_string(WEXITSTATUS(status)) + ")" +
                           (said.empty() ? std::string() : ": " + said));
}

int runWorkspaceWorker(std::istream& in, std::ostream& out) {
  try {
    const Job job = readJob(in);
    ResolvedWorkspaceRequest request = job.request;
    // Called from the computing threads one at a time: no lock needed around `out`.
    request.options.progress = [&](const AnalysisProgress& progress) {
      out << "analysis " << exactText(progress.fraction) << ' ' << progress.evaluated << ' ' << progress.inside << ' '
          << oneLine(progress.stage) << std::endl;
    };
    const ComputedEntry computed = InProcessComputation().compute(
        request, job.model, job.source, job.staging,
        [&](double fraction) { out << "storing " << exactText(fraction) << std::endl; });
    out << "done " << exactText(computed.seconds) << ' ' << exactText(computed.storing_seconds) << ' '
        << computed.poses_evaluated << ' ' << computed.voxels << ' ' << peakResidentBytes() << std::endl;
    return 0;
  } catch (const InputError& error) {
    out << "refused " << oneLine(error.what()) << std::endl;
    return 2;
  } catch (const std::exception& error) {
    out << "failed " << oneLine(error.what()) << std::endl;
    return 1;
  }
}

}  // namespace maximal_workspace
