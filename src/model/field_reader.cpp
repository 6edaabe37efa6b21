#include "model/field_reader.h"

#include <algorithm>
#include <cmath>
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
    case YAML::NodeType::Scalar: return "'" + node.Scalar() + "'";
    default: return "an undefined value";
  }
}

}  // namespace

FieldReader::FieldReader(YAML::Node node, std::string source, std::string context)
    : node_(std::move(node)), source_(std::move(source)), context_(std::move(context)) {}

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

double FieldReader::number(const char* field) const {
  return toNumber(require(field), std::string("field '") + field + "'");
}

double FieldReader::positiveLength(const char* field) const {
  const double value = number(field);
  if (value <= 0.0) fail(field, "must be a length > 0 m, got " + numberText(value));
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

Eigen::Vector3d FieldReader::unitVector(const char* field) const {
  const Eigen::Vector3d value = vector3(field);
  if (value.norm() < 1e-12) fail(field, "must be a non-zero direction, got " + vectorText(value));
  return value.normalized();
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
      failAt(entry.first, "field '" + key + "'", "unknown here (expected: " + expected + ")");
    }
  }
}

}  // namespace maximal_workspace
