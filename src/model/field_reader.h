#pragma once
// Typed, checked access to one mapping of a YAML robot file. Every failure throws an
// InputError that names the file, the line, the field and the reason, so a chain type
// can read its own fields without repeating error handling.

#include <vector>
#include <string>

#include <Eigen/Core>
#include <yaml-cpp/yaml.h>

namespace maximal_workspace {

// Lengths and coordinates in a robot file at most this (m). The kinematics squares them,
// and the singularity measure divides by a product of six squared lengths: 1e24^12 is
// still a finite double, while a rod of 1e200 m made NaN inputs and determinants that
// passed as a workspace.
constexpr double kMaxLength = 1e24;

class FieldReader {
 public:
  // `context` names the mapping in messages, e.g. "chains[2] (KC2a)". A mapping with a
  // key given twice is refused here, before any field is read.
  FieldReader(YAML::Node node, std::string source, std::string context);

  bool has(const char* field) const;
  std::string text(const char* field) const;
  std::string name(const char* field) const;              // text of letters, digits, _ - . only
  double number(const char* field) const;                 // finite
  double positiveLength(const char* field) const;         // > 0, at most kMaxLength, metres
  std::vector<double> numbers(const char* field, std::size_t count) const;  // a list of finite numbers
  Eigen::Vector3d vector3(const char* field) const;       // three finite numbers
  Eigen::Vector3d point(const char* field) const;         // three numbers within kMaxLength, metres
  Eigen::Vector3d unitVector(const char* field) const;    // normalisable, returned normalised
  FieldReader mapping(const char* field) const;
  const YAML::Node& node() const { return node_; }
  const std::string& source() const { return source_; }
  const std::string& context() const { return context_; }

  // Any key outside `known` is an error: a misspelt optional field must not pass unseen.
  void rejectUnknownFields(const std::vector<const char*>& known) const;
  [[noreturn]] void fail(const char* field, const std::string& reason) const;
  // A message for a value node found under this mapping (its own line number).
  [[noreturn]] void failAt(const YAML::Node& at, const std::string& what, const std::string& reason) const;

 private:
  void rejectRepeatedFields() const;
  YAML::Node require(const char* field) const;
  double toNumber(const YAML::Node& value, const std::string& what) const;

  YAML::Node node_;
  std::string source_;
  std::string context_;
};

// Text from the file as it is shown in messages: printable ASCII as written, single quotes
// and backslashes escaped, any other byte as \xNN, so that what a message quotes is
// unambiguous and cannot garble a terminal; cut as clippedText cuts (a 10 MB name is not
// echoed whole).
std::string escapedText(const std::string& text);

}  // namespace maximal_workspace
