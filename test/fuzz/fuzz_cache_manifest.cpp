// libFuzzer target: the reader of a cache entry's manifest.json. Any text must give the
// entry's files or a reason not to trust it, never an exception (json's type errors were
// one: a "bytes" that is not a number) or a crash; the files it gives have plain names.
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <string>
#include <vector>

#include "io/cache_manifest.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace maximal_workspace;
  const std::string text(reinterpret_cast<const char*>(data), size);
  std::vector<ManifestFile> files;
  const std::string problem =
      readManifest(text, "F", "K", {"summary.json"}, files);
  if (!problem.empty()) return 0;
  if (files.empty()) std::abort();
  for (const ManifestFile& file : files) {
    if (file.name.empty() || file.name == "." || file.name == ".." || file.name.find('/') != std::string::npos) std::abort();
  }
  return 0;
}
