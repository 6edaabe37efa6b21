#include "maximal_workspace/io/workspace_cache.h"

#include <algorithm>
#include <atomic>
#include <cctype>
#include <cerrno>
#include <csignal>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>

#include <fcntl.h>
#include <nlohmann/json.hpp>
#include <sys/file.h>
#include <sys/stat.h>
#include <unistd.h>

#include "maximal_workspace/io/checksum.h"
#include "maximal_workspace/io/text_file.h"
#include "maximal_workspace/io/workspace_files.h"
#include "maximal_workspace/io/workspace_state.h"
#include "maximal_workspace/model/input_error.h"
#include "maximal_workspace/model/vector_text.h"
#include "io/cache_manifest.h"

namespace fs = std::filesystem;

namespace maximal_workspace {

namespace {

// 3: the block-structured analysis. The state file's version is part of it: an entry whose
// workspace.bin this build cannot read has another format, not a broken file.
std::string cacheFormat() { return "maximal_workspace cache 3, state " + std::to_string(workspaceStateVersion()); }

constexpr const char* kManifest = "manifest.json";

// Why the entry does not match its manifest, or empty when it does. Only the files in
// `verify` (all when empty) are read and checksummed.
std::string entryProblem(const fs::path& entry, const std::string& key, const std::vector<std::string>& verify) {
  std::string text;
  try {
    // A regular file of bounded size: anything else planted there is refused unread.
    text = readTextFile((entry / kManifest).string(), "cache manifest");
  } catch (const InputError&) {
    return "its manifest is missing or unreadable";
  }
  std::vector<ManifestFile> files;
  if (std::string problem = readManifest(text, cacheFormat(), key, verify, files); !problem.empty()) return problem;
  for (const ManifestFile& file : files) {
    const fs::path path = entry / file.name;
    std::error_code error;
    if (!fs::is_regular_file(path, error)) return "file " + clippedText(file.name) + " is missing";
    if (file.bytes != fs::file_size(path, error)) return "file " + clippedText(file.name) + " has the wrong size";
    if (!verify.empty() && std::find(verify.begin(), verify.end(), file.name) == verify.end()) continue;
    std::string sum;
    try {
      sum = hex64(fileChecksum64(path.string()));
    } catch (const InputError&) {
      return "file " + clippedText(file.name) + " cannot be read";
    }
    if (file.checksum64 != sum) return "file " + clippedText(file.name) + " fails its checksum";
  }
  return {};
}

// Moves a directory out of the way first, so no reader sees it half removed.
void removeDirectory(const fs::path& path) {
  static std::atomic<unsigned> counter{0};
  const fs::path doomed = path.parent_path() / (".removing-" + path.filename().string() + "-" +
                                                std::to_string(::getpid()) + "-" + std::to_string(counter++));
  std::error_code error;
  fs::rename(path, doomed, error);
  fs::remove_all(error ? path : doomed, error);
}

// The entry directory opened and locked (flock `operation`), or -1 when it is not there,
// the lock is not given, or the entry was renamed away (removed) while this waited for it.
int lockedEntry(const fs::path& entry, int operation) {
  const int fd = ::open(entry.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
  if (fd < 0) return -1;
  struct stat opened {}, now {};
  if (::flock(fd, operation) != 0 || ::fstat(fd, &opened) != 0 || ::stat(entry.c_str(), &now) != 0 ||
      opened.st_ino != now.st_ino || opened.st_dev != now.st_dev) {
    ::close(fd);
    return -1;
  }
  return fd;
}

// Staging and removal directories of writers that no longer run (killed mid-write): their
// names end in -<pid>-<counter>. A writer that runs keeps its own.
void removeAbandoned(const fs::path& directory) {
  std::vector<fs::path> abandoned;
  std::error_code error;
  for (fs::directory_iterator it(directory, error), end; !error && it != end; it.increment(error)) {
    const std::string name = it->path().filename().string();
    if (name.rfind(".staging-", 0) != 0 && name.rfind(".removing-", 0) != 0) continue;
    const std::size_t last = name.rfind('-');
    const std::size_t before = last == std::string::npos || last == 0 ? std::string::npos : name.rfind('-', last - 1);
    if (before == std::string::npos) continue;
    const long pid = std::strtol(name.c_str() + before + 1, nullptr, 10);
    if (pid > 0 && ::kill(static_cast<pid_t>(pid), 0) != 0 && errno == ESRCH) abandoned.push_back(it->path());
  }
  for (const fs::path& path : abandoned) fs::remove_all(path, error);
}

// Entries are named by their key (workspaceCacheKey: 16 hex digits); nothing else in the
// directory is taken for one, so removal by age touches nothing but entries.
bool isEntryName(const std::string& name) {
  return name.size() == 16 &&
         std::all_of(name.begin(), name.end(), [](char c) { return std::isxdigit(static_cast<unsigned char>(c)) != 0; });
}

std::uint64_t directoryBytes(const fs::path& directory) {
  std::uint64_t bytes = 0;
  std::error_code error;
  for (fs::directory_iterator it(directory, error), end; !error && it != end; it.increment(error)) {
    std::error_code size_error;
    const std::uintmax_t size = it->is_regular_file(size_error) ? it->file_size(size_error) : 0;
    if (!size_error) bytes += size;
  }
  return bytes;
}

}  // namespace

std::string defaultCacheDirectory() {
  if (const char* ros_home = std::getenv("ROS_HOME")) return std::string(ros_home) + "/maximal_workspace";
  const char* home = std::getenv("HOME");
  return std::string(home ? home : ".") + "/.ros/maximal_workspace";
}

std::string workspaceRequestText(const Grid& grid, const AnalysisOptions& options) {
  std::ostringstream text;
  const GridSpec& spec = grid.spec();
  text << "variables";
  for (OutputVariable variable : spec.variables) text << ' ' << outputVariableName(variable);
  text << "\nsteps";
  for (double step : spec.steps) text << ' ' << exactText(step);
  text << "\nstart";
  for (int v = 0; v < kOutputVariableCount; ++v) text << ' ' << exactText(spec.start.value(static_cast<OutputVariable>(v)));
  text << "\nbounds";
  for (const auto& bound : spec.bounds) text << ' ' << exactText(bound[0]) << ' ' << exactText(bound[1]);
  // Only where it is not the default, so that the other grids keep their keys.
  if (grid.tiltTorsion()) text << "\norientation tilt_torsion";
  text << "\nmargin " << exactText(options.margin) << "\ndebris "
       << options.debris.min_voxels << ' ' << exactText(options.debris.min_fraction) << "\nworking_modes "
       << (options.uncoupled ? "uncoupled" : "coupled") << "\nonly_modes";
  for (const std::string& mode : options.working_modes) text << ' ' << mode;
  text << "\nstart_mode " << options.start_mode
       << "\ntransition_tolerance " << exactText(options.transition_tolerance) << "\n";
  // Only when asked for, so that the other requests keep their keys.
  if (options.conditioning) {
    text << "conditioning " << exactText(options.conditioning->threshold) << ' ' << options.conditioning->evaluations << "\n";
  }
  return text.str();
}

std::string workspaceCacheKey(const std::string& robot_file_text, const std::string& request_text) {
  std::uint64_t hash = fnv1a64(cacheFormat());
  hash = fnv1a64(robot_file_text, hash);
  hash = fnv1a64("\n--request--\n" + request_text, hash);
  return hex64(hash);
}

WorkspaceCache::WorkspaceCache(std::string directory) : directory_(std::move(directory)) {
  std::error_code error;
  fs::create_directories(directory_, error);
  if (error || !fs::is_directory(directory_)) {
    throw InputError(directory_ + ": cannot use as cache directory: " + (error ? error.message() : "not a directory"));
  }
  removeAbandoned(directory_);
}

std::string WorkspaceCache::filesSignature(const std::string& key) const {
  std::vector<std::string> files;
  std::error_code error;
  for (fs::directory_iterator it(entryPath(key), error), end; !error && it != end; it.increment(error)) {
    const std::string name = it->path().filename().string();
    if (name == kManifest) continue;
    std::error_code stat_error;
    const auto bytes = fs::file_size(it->path(), stat_error);
    const auto time = fs::last_write_time(it->path(), stat_error);
    if (stat_error) return {};
    files.push_back(name + ' ' + std::to_string(bytes) + ' ' + std::to_string(time.time_since_epoch().count()));
  }
  if (error) return {};
  std::sort(files.begin(), files.end());  // directory order is arbitrary
  std::string signature;
  for (const std::string& file : files) signature += file + '\n';
  return signature;
}

std::optional<std::string> WorkspaceCache::find(const std::string& key, std::string* problem,
                                                const std::vector<std::string>& verify) const {
  const fs::path entry = entryPath(key);
  std::error_code error;
  if (!fs::exists(entry, error)) return std::nullopt;
  if (!this->verify(key, verify, problem)) return std::nullopt;
  return entry.string();
}

bool WorkspaceCache::verify(const std::string& key, const std::vector<std::string>& files, std::string* problem) const {
  const fs::path entry = entryPath(key);
  const std::string why = entryProblem(entry, key, files);
  if (why.empty()) return true;
  if (problem != nullptr) *problem = "cache entry " + entry.string() + " is invalid (" + why + "); it was removed";
  removeDirectory(entry);
  return false;
}

std::string WorkspaceCache::stagingDirectory(const std::string& key) const {
  static std::atomic<unsigned> counter{0};
  const fs::path staging = fs::path(directory_) / (".staging-" + key + "-" + std::to_string(::getpid()) + "-" +
                                                   std::to_string(counter++));
  std::error_code error;
  fs::create_directory(staging, error);
  if (error) throw InputError(staging.string() + ": cannot create: " + error.message());
  return staging.string();
}

std::string WorkspaceCache::store(const std::string& key, const std::function<void(const std::string& directory)>& write,
                                  const std::function<void()>& tick) const {
  const std::string staging = stagingDirectory(key);
  try {
    write(staging);
    return commit(key, staging, tick);
  } catch (...) {
    removeDirectory(staging);
    throw;
  }
}

std::string WorkspaceCache::commit(const std::string& key, const std::string& staging,
                                   const std::function<void()>& tick) const {
  nlohmann::json files = nlohmann::json::object();
  for (const fs::directory_entry& file : fs::directory_iterator(staging)) {
    const std::string checksum = hex64(fileChecksum64(file.path().string(), tick));
    files[file.path().filename().string()] = {{"bytes", fs::file_size(file.path())}, {"checksum64", checksum}};
  }
  const nlohmann::json manifest = {{"format", cacheFormat()}, {"key", key}, {"files", files}};
  writeFileAtomically(staging + "/" + kManifest, manifest.dump(1) + "\n");
  const fs::path entry = entryPath(key);
  std::error_code error;
  fs::rename(staging, entry, error);
  if (!error) return entry.string();
  // The key is taken: a concurrent computation finished first, or a broken entry sits there.
  std::string problem;
  if (find(key, &problem)) {
    removeDirectory(staging);
    return entry.string();
  }
  fs::rename(staging, entry, error);
  if (error) {
    removeDirectory(staging);
    throw InputError(entry.string() + ": cannot store cache entry: " + error.message());
  }
  return entry.string();
}

std::vector<CacheEntryUse> WorkspaceCache::entries() const {
  std::vector<CacheEntryUse> entries;
  std::error_code error;
  for (fs::directory_iterator it(directory_, error), end; !error && it != end; it.increment(error)) {
    const std::string name = it->path().filename().string();
    std::error_code entry_error;
    if (!isEntryName(name) || !it->is_directory(entry_error)) continue;
    CacheEntryUse entry{name, directoryBytes(it->path()), fs::last_write_time(it->path() / kManifest, entry_error)};
    if (entry_error) entry.last_use = fs::file_time_type::min();  // no manifest: a broken entry, the first to go
    entries.push_back(entry);
  }
  return entries;
}

void WorkspaceCache::touch(const std::string& key) const {
  std::error_code ignored;  // an entry removed meanwhile has no use to record
  fs::last_write_time(fs::path(entryPath(key)) / kManifest, fs::file_time_type::clock::now(), ignored);
}

void WorkspaceCache::remove(const std::string& key) const { removeDirectory(entryPath(key)); }

std::shared_ptr<const void> WorkspaceCache::hold(const std::string& key) const {
  class Lock {
   public:
    explicit Lock(int fd) : fd_(fd) {}
    Lock(const Lock&) = delete;
    Lock& operator=(const Lock&) = delete;
    ~Lock() { ::close(fd_); }  // releases it

   private:
    int fd_;
  };
  const int fd = lockedEntry(entryPath(key), LOCK_SH);
  if (fd < 0) return nullptr;
  return std::make_shared<const Lock>(fd);
}

bool WorkspaceCache::removeUnlessHeld(const std::string& key) const {
  const int fd = lockedEntry(entryPath(key), LOCK_EX | LOCK_NB);
  if (fd < 0) return false;
  // Renamed away under the lock: a reader that waited for it finds the entry gone.
  removeDirectory(entryPath(key));
  ::close(fd);
  return true;
}

}  // namespace maximal_workspace
