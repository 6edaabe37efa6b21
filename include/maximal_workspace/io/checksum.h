#pragma once
// FNV-1a, 64 bits: cache keys and corruption checks of cache files. Not a defence against
// a malicious cache, which the cache does not claim to be.

#include <cstdint>
#include <functional>
#include <string>

namespace maximal_workspace {

std::uint64_t fnv1a64(const std::string& bytes, std::uint64_t hash = 0xcbf29ce484222325ull);
// The same idea eight bytes at a time (about eight times faster), for file contents: every
// step is a bijection of the state, so any changed word changes the result.
std::uint64_t wordChecksum64(const std::string& bytes);
// wordChecksum64 of a file's bytes, read in pieces of 16 MiB (never the whole file in
// memory: a cache file is hundreds of megabytes at fine steps); `tick` is called after each
// piece, and what it throws (Cancelled) passes on. Throws InputError when the file cannot
// be read.
std::uint64_t fileChecksum64(const std::string& path, const std::function<void()>& tick = {});
std::string hex64(std::uint64_t value);  // 16 lowercase hex digits

}  // namespace maximal_workspace
