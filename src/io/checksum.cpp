#include "maximal_workspace/io/checksum.h"

#include <cstdio>
#include <cstring>

namespace maximal_workspace {

std::uint64_t fnv1a64(const std::string& bytes, std::uint64_t hash) {
  for (unsigned char byte : bytes) {
    hash ^= byte;
    hash *= 0x100000001b3ull;
  }
  return hash;
}

std::uint64_t wordChecksum64(const std::string& bytes) {
  std::uint64_t hash = 0xcbf29ce484222325ull ^ bytes.size();
  const std::size_t words = bytes.size() / 8;
  for (std::size_t i = 0; i < words; ++i) {
    std::uint64_t word;
    std::memcpy(&word, bytes.data() + 8 * i, 8);
    hash = (hash ^ word) * 0x100000001b3ull;
  }
  return fnv1a64(bytes.substr(8 * words), hash);
}

std::string hex64(std::uint64_t value) {
  char buffer[17];
  std::snprintf(buffer, sizeof buffer, "%016llx", static_cast<unsigned long long>(value));
  return buffer;
}

}  // namespace maximal_workspace
