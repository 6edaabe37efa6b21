#include "model/field_reader.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <map>
#include <string>

#include "maximal_workspace/model/input_error.h"
#include "maximal_workspace/model/vector_text.h"

namespace maximal_workspace {

namespace {

std::string location(const std::string& source, const YAML::Node& node) {
  const YAML::Mark mark = node.Mark();
  if (mark.line < 0) return source;
  return source + ":" + std::to_string(mark.line + 1);
}

std::string describeNode(const YAML::Node& node) {
  switch (node.Type()) {
    case YAML::NodeType::Null: return "nothing";
    case YAML::NodeType::Sequence: return "a list";
    case YAML::NodeType::Map: return "a mapping";
    case YAML::NodeType::Scalar: return "'" + escapedText(node.Scalar()) + "'";
    default: return "an undefined value";
  }
}

// Names go into URDF attributes, JSON, CSV headers and ROS messages: this set needs no
// escaping in any of them.
bool isNameCharacter(unsigned char c) {
  return (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') || c == '_' || c == '-' || c == '.';
}

}  // namespace

std::string escapedText(const std::string& text) {
  std::string escaped;
  for (const unsigned char c : clippedText(text)) {
    if (c == '\\' || c == '\'') {
      escaped += '\\';
      escaped += static_cast<char>(c);
    } else if (c >= 0x20 && c < 0x7f) {
      escaped += static_cast<char>(c);
    } else {
      char hex[5];
      std::snprintf(hex, sizeof hex, "\\x%02x", c);
      escaped += hex;
    }
  }
  return escaped;
}

FieldReader::FieldReader(YAML::Node node, std::string source, std::string context)
    : node_(std::move(node)), source_(std::move(source)), context_(std::move(context)) {
  if (node_.IsMap()) rejectRepeatedFields();
}

// yaml-cpp keeps every copy of a repeated key and a lookup finds the first: the second
// value would be ignored without a word.
void FieldReader::rejectRepeatedFields() const {
  std::map<std::string, int> first_line;
  for (const auto& entry : node_) {
    if (!entry.first.IsScalar()) continue;  // rejectUnknownFields refuses it
    const int line = entry.first.Mark().line + 1;
    const auto [first, added] = first_line.emplace(entry.first.Scalar(), line);
    if (added) continue;
    failAt(entry.first, "field '" + escapedText(entry.first.Scalar()) + "'",
           first->second == line ? "given twice on this line"
                                 : "given twice (lines " + std::to_string(first->second) + " and " + std::to_string(line) + ")");
  }
}

bool FieldReader::has(const char* field) const { return node_.IsMap() && node_[field].IsDefined(); }

void FieldReader::fail(const char* field, const std::string& reason) const {
  const YAML::Node value = has(field) ? node_[field] : node_;
  throw InputError(location(source_, value) + ": " + context_ + ": field '" + field + "': " + reason);
}

void FieldReader::failAt(const YAML::Node& at, const std::string& what, const std::string& reason) const {
  throw InputError(location(source_, at) + ": " + context_ + ": " + what + ": " + reason);
}

YAML::Node FieldReader::require(const char* field) const {
  if (!node_.IsMap()) failAt(node_, "value", "must be a mapping of fields, got " + describeNode(node_));
  if (!has(field)) fail(field, "missing");
  return node_[field];
}

double FieldReader::toNumber(const YAML::Node& value, const std::string& what) const {
  if (!value.IsScalar()) failAt(value, what, "must be a number, got " + describeNode(value));
  double number = 0.0;
  try {
    number = value.as<double>();
  } catch (const YAML::Exception&) {
    failAt(value, what, "must be a number, got " + describeNode(value));
  }
  if (!std::isfinite(number)) failAt(value, what, "must be finite, got " + describeNode(value));
  return number;
}

std::string FieldReader::text(const char* field) const {
  const YAML::Node value = require(field);
  if (!value.IsScalar() || value.Scalar().empty()) fail(field, "must be a non-empty text, got " + describeNode(value));
  return value.Scalar();
}

std::string FieldReader::name(const char* field) const {
  const std::string value = text(field);
  const auto bad = std::find_if_not(value.begin(), value.end(), isNameCharacter);
  if (bad == value.end()) return value;
  // The whole character: a UTF-8 lead byte with its continuation bytes.
  auto end = bad + 1;
  while (end != value.end() && (static_cast<unsigned char>(*end) & 0xC0) == 0x80) ++end;
  fail(field, "'" + escapedText(value) + "' has '" + escapedText(std::string(bad, end)) +
                  "', not allowed in a name (letters, digits, _ - .)");
}

double FieldReader::number(const char* field) const {
  return toNumber(require(field), std::string("field '") + field + "'");
}

double FieldReader::positiveLength(const char* field) const {
  const double value = number(field);
  if (value <= 0.0) fail(field, "must be a length > 0 m, got " + numberText(value));
  if (value > kMaxLength) fail(field, "must be a length of at most " + numberText(kMaxLength) + " m, got " + numberText(value));
  return value;
}

std::vector<double> FieldReader::numbers(const char* field, std::size_t count) const {
  const YAML::Node value = require(field);
  if (!value.IsSequence() || value.size() != count) {
    fail(field, "must be a list of " + std::to_string(count) + " numbers, got " + describeNode(value) +
                    (value.IsSequence() ? " of " + std::to_string(value.size()) : ""));
  }
  std::vector<double> result(count);
  for (std::size_t i = 0; i < count; ++i) {
    result[i] = toNumber(value[i], std::string("field '") + field + "' element " + std::to_string(i));
  }
  return result;
}

Eigen::Vector3d FieldReader::vector3(const char* field) const {
  const std::vector<double> value = numbers(field, 3);
  return Eigen::Vector3d(value[0], value[1], value[2]);
}

Eigen::Vector3d FieldReader::point(const char* field) const {
  const Eigen::Vector3d value = vector3(field);
  if (value.cwiseAbs().maxCoeff() > kMaxLength) {
    fail(field, "must be a point within " + numberText(kMaxLength) + " m of the origin along each axis, got " +
                    vectorText(value));
  }
  return value;
}

Eigen::Vector3d FieldReader::unitVector(const char* field) const {
  const Eigen::Vector3d value = vector3(field);
  // Finite components can still have a norm that overflows (1e300: the direction becomes
  // zero) or underflows (0, 1e-160: none, or an inexact one).
  const Eigen::Vector3d unit = value.normalized();
  if (!(std::abs(unit.norm() - 1.0) < 1e-9)) {
    fail(field, "must be a non-zero direction of finite length, got " + vectorText(value));
  }
  return unit;
}

FieldReader FieldReader::mapping(const char* field) const {
  const YAML::Node value = require(field);
  if (!value.IsMap()) fail(field, "must be a mapping of fields, got " + describeNode(value));
  return FieldReader(value, source_, context_ == "robot" ? field : context_ + "." + field);
}

void FieldReader::rejectUnknownFields(const std::vector<const char*>& known) const {
  if (!node_.IsMap()) failAt(node_, "value", "must be a mapping of fields, got " + describeNode(node_));
  for (const auto& entry : node_) {
    const std::string key = entry.first.IsScalar() ? entry.first.Scalar() : std::string();
    const bool listed = std::any_of(known.begin(), known.end(), [&](const char* k) { return key == k; });
    if (!listed) {
      std::string expected;
      for (const char* k : known) expected += std::string(expected.empty() ? "" : ", ") + k;
      // A key that could be a field name is shown; any other text is not echoed: a wrong
      // path's first line (a password file's) would be, to whoever reads the message.
      const bool name = !key.empty() && key.size() <= 64 && std::all_of(key.begin(), key.end(), isNameCharacter);
      failAt(entry.first, name ? "field '" + key + "'" : "a key that is no field name (" + std::to_string(key.size()) + " bytes)",
             "unknown here (expected: " + expected + ")");
    }
  }
}

}  // namespace maximal_workspace
