#pragma once
// A directory of computed workspaces, one entry per robot file content and request.
// An entry is a directory <key>/ holding the files of writeWorkspaceFiles and a
// manifest.json (format, key, size and checksum of every file). It is written under a
// staging name and renamed into place once complete, so a reader never sees half an
// entry; on lookup a manifest that does not match (other format, another key, a file
// missing, truncated or altered) makes the entry count as absent: it is removed and the
// caller told why, and the workspace is computed again.

#include <cstdint>
#include <filesystem>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "maximal_workspace/regions/workspace_analysis.h"

namespace maximal_workspace {

// $ROS_HOME/maximal_workspace, else ~/.ros/maximal_workspace: one cache for the mow tool
// and the nodes.
std::string defaultCacheDirectory();

// Canonical text of everything that decides a result besides the robot file: the
// resolved grid (variables, steps, start, bounds) and the analysis options. Thread count
// and voxel budget are left out: they do not change a result.
std::string workspaceRequestText(const Grid& grid, const AnalysisOptions& options);
// 16 hex digits over the robot file's bytes, the request text and the cache format (which
// includes the workspace.bin version).
std::string workspaceCacheKey(const std::string& robot_file_text, const std::string& request_text);

// An entry as least-recently-used removal sees it.
struct CacheEntryUse {
  std::string key;
  std::uint64_t bytes = 0;  // its files on disk, manifest included
  std::filesystem::file_time_type last_use;
};

class WorkspaceCache {
 public:
  // Creates the directory when missing; throws InputError when it cannot. Removes what
  // writers killed mid-write left (their staging directories).
  explicit WorkspaceCache(std::string directory);

  const std::string& directory() const { return directory_; }
  std::string entryPath(const std::string& key) const { return directory_ + "/" + key; }
  // The entry's path when present and valid; otherwise nullopt, and `problem` is set when
  // an invalid entry was found (and removed). `verify`: the files whose size and checksum
  // are checked now (empty: all); check the others with verify() before using them.
  std::optional<std::string> find(const std::string& key, std::string* problem,
                                  const std::vector<std::string>& verify = {}) const;
  // The names, sizes and modification times of the entry's files (its manifest left out: a
  // use touches it); empty when the entry is missing. Rewriting any file changes it.
  std::string filesSignature(const std::string& key) const;
  // Checks files of a found entry against its manifest; when one fails, removes the entry
  // and says why in `problem`.
  bool verify(const std::string& key, const std::vector<std::string>& files, std::string* problem) const;
  // Writes an entry: `write` fills a new staging directory, which is then committed. When
  // writing or committing fails, the staging directory is removed and the exception passes
  // on, so a failed write (a full disk, a killed writer excepted) leaves nothing behind.
  // Returns the entry's path. `tick`: as commit's.
  std::string store(const std::string& key, const std::function<void(const std::string& directory)>& write,
                    const std::function<void()>& tick = {}) const;
  // A new empty directory inside the cache to write an entry into.
  std::string stagingDirectory(const std::string& key) const;
  // Writes the manifest of the staging directory's files and renames it into place. When
  // a valid entry for the key appeared meanwhile (a concurrent computation), keeps that one
  // and removes the staging directory. Returns the entry's path. `tick` is called as the
  // files are checksummed (every 16 MiB); what it throws (Cancelled) passes on.
  std::string commit(const std::string& key, const std::string& staging, const std::function<void()>& tick = {}) const;

  // Every entry (staging and removal directories left out) with its size and last use.
  std::vector<CacheEntryUse> entries() const;
  // Records a use of the entry now, as its manifest's modification time: it outlives this
  // process, and the manifest's bytes (hence its checks) stay as they are.
  void touch(const std::string& key) const;
  // Removes the entry, renamed out of the way first so no reader sees it half removed.
  void remove(const std::string& key) const;
  // A shared lock (flock) on the entry for as long as the returned handle lives, in this
  // process or any other: removeUnlessHeld leaves the entry alone meanwhile. Null when
  // there is no entry (or it was removed while the lock was taken).
  std::shared_ptr<const void> hold(const std::string& key) const;
  // Removes the entry unless a holder has it (a non-blocking exclusive lock): false then.
  bool removeUnlessHeld(const std::string& key) const;

 private:
  std::string directory_;
};

}  // namespace maximal_workspace
