#pragma once
// FNV-1a, 64 bits: cache keys and corruption checks of cache files. Not a defence against
// a malicious cache, which the cache does not claim to be.

#include <cstdint>
#include <string>

namespace maximal_workspace {

std::uint64_t fnv1a64(const std::string& bytes, std::uint64_t hash = 0xcbf29ce484222325ull);
// The same idea eight bytes at a time (about eight times faster), for file contents: every
// step is a bijection of the state, so any changed word changes the result.
std::uint64_t wordChecksum64(const std::string& bytes);
std::string hex64(std::uint64_t value);  // 16 lowercase hex digits

}  // namespace maximal_workspace
