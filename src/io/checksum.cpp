#include "maximal_workspace/io/checksum.h"

#include <algorithm>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <fstream>

#include "maximal_workspace/model/input_error.h"

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

std::uint64_t fileChecksum64(const std::string& path, const std::function<void()>& tick) {
  std::ifstream in(path, std::ios::binary | std::ios::ate);
  if (!in) throw InputError(path + ": cannot read to checksum it (" + std::strerror(errno) + ")");
  const std::uint64_t size = static_cast<std::uint64_t>(in.tellg());
  in.seekg(0);
  std::uint64_t hash = 0xcbf29ce484222325ull ^ size;
  // A multiple of 8 bytes: a word never straddles two pieces, so the result is
  // wordChecksum64's of the whole. No larger than the file: a cached lookup checksums a
  // summary of a few hundred KB, and zeroing 16 MiB for it took 75 ms of CPU beside four
  // fine computations (the server's cached answers then went over 100 ms).
  constexpr std::uint64_t kPieceBytes = std::uint64_t{16} << 20;
  std::string piece(static_cast<std::size_t>(std::min(kPieceBytes, (size / 8 + 1) * 8)), '\0');
  while (in.read(piece.data(), static_cast<std::streamsize>(piece.size())), in.gcount() > 0) {
    const std::size_t got = static_cast<std::size_t>(in.gcount()), words = got / 8;
    for (std::size_t i = 0; i < words; ++i) {
      std::uint64_t word;
      std::memcpy(&word, piece.data() + 8 * i, 8);
      hash = (hash ^ word) * 0x100000001b3ull;
    }
    if (got < piece.size()) return fnv1a64(piece.substr(8 * words, got - 8 * words), hash);
    if (tick) tick();
  }
  if (in.bad()) throw InputError(path + ": cannot read to checksum it (read error)");
  return hash;
}

std::string hex64(std::uint64_t value) {
  char buffer[17];
  std::snprintf(buffer, sizeof buffer, "%016llx", static_cast<unsigned long long>(value));
  return buffer;
}

}  // namespace maximal_workspace
