#pragma once
// A cache entry's manifest.json: the files it lists, read and checked before any of them
// is looked at. Internal to the cache (io/workspace_cache.cpp); test/fuzz/fuzz_cache_manifest.cpp
// feeds it arbitrary text.

#include <cstdint>
#include <string>
#include <vector>

namespace maximal_workspace {

struct ManifestFile {
  std::string name;        // a plain file name in the entry
  std::uint64_t bytes = 0;
  std::string checksum64;  // hex; empty when the manifest gives none (the file then fails its check)
};

// The files of a manifest in `format` for `key`, every name in `verify` among them; or
// why the entry cannot be trusted, as the cache reports it. Any text gives one or the
// other: nothing here throws for what the file holds.
std::string readManifest(const std::string& text, const std::string& format, const std::string& key,
                         const std::vector<std::string>& verify, std::vector<ManifestFile>& files);

}  // namespace maximal_workspace
