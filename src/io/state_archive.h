#pragma once
// The two directions of a binary state file behind one interface, so each stored type is
// described once: describe(archive, value) writes the value with a StateWriter and reads
// it back with a StateReader, whose checks (check(), and every length against the bytes
// left) make a damaged or hostile file fail with a message instead of a wrong or huge
// allocation. Numbers are stored in the machine's byte order, as the cache is local.

#include <cstdint>
#include <istream>
#include <ostream>
#include <string>
#include <type_traits>
#include <vector>

#include "maximal_workspace/model/input_error.h"

namespace maximal_workspace {

class StateWriter {
 public:
  static constexpr bool kReading = false;
  explicit StateWriter(std::ostream& out) : out_(out) {}

  template <class T>
  void value(const T& v) {
    static_assert(std::is_arithmetic<T>::value, "plain numbers only: no padding bytes in the file");
    out_.write(reinterpret_cast<const char*>(&v), sizeof v);
  }
  template <class T>
  void array(const T* data, std::size_t count) {
    static_assert(std::is_arithmetic<T>::value, "plain numbers only");
    out_.write(reinterpret_cast<const char*>(data), static_cast<std::streamsize>(count * sizeof(T)));
  }
  template <class T>
  void values(const std::vector<T>& v) {
    value<std::uint64_t>(v.size());
    array(v.data(), v.size());
  }
  void text(const std::string& s) {
    value<std::uint64_t>(s.size());
    out_.write(s.data(), static_cast<std::streamsize>(s.size()));
  }
  // A list whose items `describe` writes; `min_item_bytes` matters only to the reader.
  template <class Item, class Describe>
  void items(const std::vector<Item>& v, std::size_t /*min_item_bytes*/, const Describe& describe) {
    value<std::uint64_t>(v.size());
    for (const Item& item : v) describe(const_cast<Item&>(item));  // read, never changed, when writing
  }
  void check(bool, const char*) const {}
  void checkFits(std::uint64_t, std::size_t) const {}
  // A count the reader needs before allocating; written as is.
  void count(std::uint64_t& n, std::size_t) { value(n); }

 private:
  std::ostream& out_;
};

class StateReader {
 public:
  static constexpr bool kReading = true;
  StateReader(std::istream& in, std::string source) : in_(in), source_(std::move(source)) {
    const std::streampos here = in_.tellg();
    in_.seekg(0, std::ios::end);
    end_ = in_.tellg();
    in_.seekg(here);
  }

  [[noreturn]] void fail(const std::string& reason) const {
    throw InputError(source_ + ": not a usable workspace state file: " + reason);
  }
  void check(bool ok, const char* reason) const {
    if (!ok) fail(reason);
  }
  template <class T>
  void value(T& v) {
    static_assert(std::is_arithmetic<T>::value, "plain numbers only");
    if (!in_.read(reinterpret_cast<char*>(&v), sizeof v)) fail("truncated");
  }
  // A flag's byte must be 0 or 1: any other is no value of a bool (undefined to load).
  void value(bool& v) {
    std::uint8_t byte = 0;
    value(byte);
    check(byte <= 1, "a flag is neither 0 nor 1");
    v = byte == 1;
  }
  template <class T>
  void array(T* data, std::size_t count) {
    if (!in_.read(reinterpret_cast<char*>(data), static_cast<std::streamsize>(count * sizeof(T)))) fail("truncated");
  }
  // Refuses `n` items of at least `item_bytes` each that cannot fit in the bytes left:
  // what bounds every allocation by the file's size.
  void checkFits(std::uint64_t n, std::size_t item_bytes) {
    const std::uint64_t left = static_cast<std::uint64_t>(end_ - in_.tellg());
    if (item_bytes > 0 && n > left / item_bytes) fail("a length runs past the end of the file");
  }
  // A count of items of at least `item_bytes` each, checked the same way.
  void count(std::uint64_t& n, std::size_t item_bytes) {
    value(n);
    checkFits(n, item_bytes);
  }
  template <class T>
  void values(std::vector<T>& v) {
    std::uint64_t n = 0;
    count(n, sizeof(T));
    v.resize(n);
    array(v.data(), v.size());
  }
  void text(std::string& s) {
    std::uint64_t n = 0;
    count(n, 1);
    s.resize(n);
    if (!in_.read(s.data(), static_cast<std::streamsize>(n))) fail("truncated");
  }
  template <class Item, class Describe>
  void items(std::vector<Item>& v, std::size_t min_item_bytes, const Describe& describe) {
    std::uint64_t n = 0;
    count(n, min_item_bytes);
    v.assign(n, Item());
    for (Item& item : v) describe(item);
  }
  bool atEnd() { return in_.peek() == std::char_traits<char>::eof(); }

 private:
  std::istream& in_;
  std::string source_;
  std::streampos end_;
};

}  // namespace maximal_workspace
