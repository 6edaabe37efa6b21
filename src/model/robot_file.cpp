#include "maximal_workspace/model/robot_file.h"

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "maximal_workspace/io/text_file.h"
#include "maximal_workspace/kinematics/constraints.h"
#include "maximal_workspace/kinematics/inverse_kinematics.h"
#include "model/chain_types.h"
#include "model/field_reader.h"
#include "maximal_workspace/model/input_error.h"
#include "maximal_workspace/model/vector_text.h"

namespace maximal_workspace {

namespace {

const std::vector<const char*> kTopFields = {"name", "output_variables", "inputs", "chains", "reference", "clearance"};
const std::vector<const char*> kInputFields = {"name", "limits"};
const std::vector<const char*> kCommonChainFields = {"name",          "type",         "input",     "rod_length",
                                                     "platform_node", "joint_limits", "rod_radius"};
const std::vector<const char*> kJointLimitFields = {"fixed_end", "platform_end"};
const std::vector<const char*> kConeFields = {"axis", "half_angle"};
const std::vector<const char*> kReferenceFields = {"position", "orientation", "inputs"};

YAML::Node requireList(const FieldReader& fields, const char* field) {
  if (!fields.has(field)) fields.fail(field, "missing");
  const YAML::Node list = fields.node()[field];
  if (!list.IsSequence() || list.size() == 0) fields.fail(field, "must be a non-empty list");
  return list;
}

std::vector<OutputVariable> readOutputVariables(const FieldReader& top) {
  const YAML::Node list = requireList(top, "output_variables");
  std::vector<OutputVariable> variables;
  for (const auto& item : list) {
    const std::string name = item.IsScalar() ? item.Scalar() : std::string();
    const auto variable = parseOutputVariable(name);
    if (!variable) {
      top.failAt(item, "field 'output_variables'", "unknown variable '" + escapedText(name) + "' (expected x y z phi theta psi)");
    }
    if (std::find(variables.begin(), variables.end(), *variable) != variables.end()) {
      top.failAt(item, "field 'output_variables'", "'" + name + "' is listed twice");
    }
    variables.push_back(*variable);
  }
  // Canonical order X Y Z phi theta psi: the sign of det J_DKP, which names assembly
  // modes, must not depend on the order a file lists them in.
  std::sort(variables.begin(), variables.end());
  int rotational = 0;
  bool has_phi = false;
  for (OutputVariable v : variables) {
    rotational += isRotational(v);
    has_phi |= v == OutputVariable::Phi;
  }
  // The twist form needs angular velocity components: all three, or wz alone (planar).
  if (!(rotational == 0 || rotational == 3 || (rotational == 1 && has_phi))) {
    top.fail("output_variables", "rotational DOF must be none, phi alone (planar) or all of phi theta psi");
  }
  return variables;
}

// The context of a list item in messages: "inputs[1] (KC2)".
std::string itemContext(const char* list, std::size_t index, const YAML::Node& item) {
  std::string context = std::string(list) + "[" + std::to_string(index) + "]";
  // A missing key of a const node is an invalid node: only IsDefined() may be asked of it.
  const YAML::Node name = item.IsMap() ? item["name"] : YAML::Node();
  if (name.IsDefined() && name.IsScalar()) context += " (" + escapedText(name.Scalar()) + ")";
  return context;
}

// Before any item is read, so that a file of thousands of chains or inputs is refused at
// once, and every later check across items runs over at most kMaxChains of them.
void checkCounts(const FieldReader& top, int dof) {
  const std::size_t chains = requireList(top, "chains").size();
  if (chains != static_cast<std::size_t>(dof)) {
    top.fail("chains", "a fully-parallel mechanism has one chain per DOF: " + std::to_string(chains) + " chains for " +
                           std::to_string(dof) + " output variables");
  }
  const std::size_t inputs = requireList(top, "inputs").size();
  if (inputs > chains) {
    top.fail("inputs", "each input drives at least one chain: " + std::to_string(inputs) + " inputs for " +
                           std::to_string(chains) + " chains");
  }
}

// Readers of the inputs and chains, kept so that checks across fields can point at the
// line of the item concerned.
struct ItemReaders {
  std::vector<FieldReader> inputs;
  std::vector<FieldReader> chains;
};

std::vector<Input> readInputs(const FieldReader& top, ItemReaders& readers) {
  const YAML::Node list = requireList(top, "inputs");
  std::vector<Input> inputs;
  for (std::size_t i = 0; i < list.size(); ++i) {
    const FieldReader fields(list[i], top.source(), itemContext("inputs", i, list[i]));
    fields.rejectUnknownFields(kInputFields);
    Input input;
    input.name = fields.name("name");
    for (const Input& other : inputs) {
      if (other.name == input.name) fields.fail("name", "input '" + input.name + "' is declared twice");
    }
    if (fields.has("limits")) {
      const std::vector<double> range = fields.numbers("limits", 2);
      if (!(range[0] < range[1])) fields.fail("limits", "min must be below max");
      input.limits = std::array<double, 2>{range[0], range[1]};
    }
    inputs.push_back(std::move(input));
    readers.inputs.push_back(fields);
  }
  return inputs;
}

std::optional<JointCone> readCone(const FieldReader& joints, const char* end) {
  if (!joints.has(end)) return std::nullopt;
  const FieldReader fields = joints.mapping(end);
  fields.rejectUnknownFields(kConeFields);
  JointCone cone;
  cone.axis = fields.unitVector("axis");
  cone.half_angle = fields.number("half_angle");
  if (!(cone.half_angle > 0.0 && cone.half_angle <= M_PI)) {
    fields.fail("half_angle", "must be an angle in (0, pi] rad, got " + numberText(cone.half_angle));
  }
  return cone;
}

ChainLimits readChainLimits(const FieldReader& fields) {
  ChainLimits limits;
  if (fields.has("joint_limits")) {
    const FieldReader joints = fields.mapping("joint_limits");
    joints.rejectUnknownFields(kJointLimitFields);
    limits.fixed_end = readCone(joints, "fixed_end");
    limits.platform_end = readCone(joints, "platform_end");
  }
  if (fields.has("rod_radius")) limits.rod_radius = fields.positiveLength("rod_radius");
  return limits;
}

void readChains(const FieldReader& top, RobotModel& model, ItemReaders& readers) {
  const YAML::Node list = requireList(top, "chains");
  for (std::size_t i = 0; i < list.size(); ++i) {
    const FieldReader fields(list[i], top.source(), itemContext("chains", i, list[i]));
    ChainCommon common;
    common.name = fields.name("name");
    const std::string type_name = fields.text("type");
    const ChainType* type = findChainType(type_name);
    if (type == nullptr) {
      std::string known;
      for (const ChainType& t : chainTypes()) known += std::string(known.empty() ? "" : ", ") + t.name;
      fields.fail("type", "unknown chain type '" + escapedText(type_name) + "' (known: " + known + ")");
    }
    std::vector<const char*> allowed = kCommonChainFields;
    allowed.insert(allowed.end(), type->fields.begin(), type->fields.end());
    fields.rejectUnknownFields(allowed);
    if (model.chainIndex(common.name) >= 0) fields.fail("name", "chain '" + common.name + "' is declared twice");
    common.input = fields.text("input");
    const int input = model.inputIndex(common.input);
    if (input < 0) fields.fail("input", "'" + escapedText(common.input) + "' is not declared under inputs");
    common.rod_length = fields.positiveLength("rod_length");
    common.platform_node = fields.point("platform_node");
    common.limits = readChainLimits(fields);
    ChainPtr chain = type->fromFields(fields, std::move(common));
    model.inputs[input].kind = chain->inputKind();
    model.inputs[input].chains.push_back(model.chainCount());
    model.chain_input.push_back(input);
    model.chains.push_back(std::move(chain));
    readers.chains.push_back(fields);
  }
}

void readReference(const FieldReader& top, RobotModel& model) {
  const FieldReader reference = top.mapping("reference");
  reference.rejectUnknownFields(kReferenceFields);
  model.reference.pose.position = reference.point("position");
  if (reference.has("orientation")) model.reference.pose.euler_zyz = reference.vector3("orientation");
  if (!reference.has("inputs")) return;
  const FieldReader inputs = reference.mapping("inputs");
  std::vector<const char*> names;
  for (const Input& input : model.inputs) names.push_back(input.name.c_str());
  inputs.rejectUnknownFields(names);
  for (const Input& input : model.inputs) {
    const double value = inputs.number(input.name.c_str());
    // An input driving no chain is reported by checkMechanism.
    if (input.limits && !input.chains.empty() &&
        model.chains[input.chains.front()]->inputMargin(value, *input.limits) < 0.0) {
      inputs.fail(input.name.c_str(), "value " + numberText(value) + " is outside the input's limits");
    }
    model.reference.inputs.push_back(value);
  }
}

// The reference configuration must keep the robot's limits: with reference inputs, the
// configuration they give; without, some working mode.
void checkReferenceLimits(const FieldReader& top, const RobotModel& model) {
  const RobotConstraints constraints(model);
  if (!constraints.active()) return;
  const Pose& pose = model.reference.pose;
  const IkpResult ikp = solveIkp(model, pose);
  const FieldReader reference = top.mapping("reference");
  if (!model.reference.inputs.empty()) {
    const WorkingModeIdentification found = identifyWorkingMode(model, ikp, model.reference.inputs);
    if (!found.found) return;  // mow info reports why
    const std::string broken = constraints.violationText(pose, ikp, found.uncoupled);
    if (!broken.empty()) reference.fail("inputs", "the reference configuration breaks a limit: " + broken);
    return;
  }
  std::string first_reason;
  for (const WorkingMode& mode : coupledWorkingModes(model)) {
    const std::string broken = constraints.violationText(pose, ikp, mode);
    if (broken.empty()) return;
    if (first_reason.empty()) first_reason = mode.name + ": " + broken;
  }
  reference.fail("position", "no working mode keeps the robot's limits at the reference pose (" + first_reason + ")");
}

// Consistency that no single field shows.
void checkMechanism(const FieldReader& top, const ItemReaders& readers, RobotModel& model) {
  const Eigen::Matrix3d rotation = model.reference.pose.rotation();
  for (int i = 0; i < model.inputCount(); ++i) {
    const Input& input = model.inputs[i];
    if (input.chains.empty()) readers.inputs[i].fail("name", "input '" + input.name + "' is driven by no chain");
    if (input.kind == InputKind::Revolute && input.limits && (*input.limits)[1] - (*input.limits)[0] > 2.0 * M_PI) {
      readers.inputs[i].fail("limits", "a revolute range spans at most one turn (max - min <= 2 pi)");
    }
    const Chain& first = *model.chains[input.chains.front()];
    for (std::size_t k = 1; k < input.chains.size(); ++k) {
      const Chain& other = *model.chains[input.chains[k]];
      const Eigen::Vector3d offset = rotation * (other.platformNode() - first.platformNode());
      const std::string mismatch = first.translateMismatch(other, offset);
      if (!mismatch.empty()) {
        readers.chains[input.chains[k]].fail(
            "input", "chains '" + first.name() + "' and '" + other.name() + "' share input '" + input.name +
                         "' but are not parallel translates of each other: " + mismatch);
      }
    }
  }
  double sum_squares = 0.0;
  for (const ChainPtr& chain : model.chains) sum_squares += chain->platformNode().squaredNorm();
  const bool rotational = std::any_of(model.output_variables.begin(), model.output_variables.end(), isRotational);
  if (rotational) {
    model.characteristic_length = std::sqrt(sum_squares / model.chainCount());
    if (model.characteristic_length < 1e-9) {
      top.fail("chains", "rotational DOF need platform nodes away from the TCP; all are at it");
    }
  }
  for (const ChainPtr& chain : model.chains) {
    const ChainSolution solution = chain->solve(model.reference.pose.toBase(chain->platformNode()));
    if (!solution.assembled) {
      top.mapping("reference").fail("position", "chain '" + chain->name() + "' cannot be assembled at the reference pose (discriminant " +
                                numberText(solution.discriminant) + " < 0)");
    }
  }
  checkReferenceLimits(top, model);
}

// Offset of the first byte that does not start a well-formed UTF-8 sequence (RFC 3629: no
// overlong forms, surrogates or code points over U+10FFFF), or npos.
std::size_t firstInvalidUtf8(const std::string& text) {
  for (std::size_t at = 0; at < text.size();) {
    const unsigned char lead = static_cast<unsigned char>(text[at]);
    std::size_t length = 1;
    unsigned char low = 0x80, high = 0xBF;  // the range of the second byte
    if (lead >= 0xC2 && lead <= 0xDF) {
      length = 2;
    } else if (lead >= 0xE0 && lead <= 0xEF) {
      length = 3;
      if (lead == 0xE0) low = 0xA0;
      if (lead == 0xED) high = 0x9F;
    } else if (lead >= 0xF0 && lead <= 0xF4) {
      length = 4;
      if (lead == 0xF0) low = 0x90;
      if (lead == 0xF4) high = 0x8F;
    } else if (lead >= 0x80) {
      return at;
    }
    if (text.size() - at < length) return at;
    for (std::size_t k = 1; k < length; ++k) {
      const unsigned char next = static_cast<unsigned char>(text[at + k]);
      if (next < (k == 1 ? low : 0x80) || next > (k == 1 ? high : 0xBF)) return at;
    }
    at += length;
  }
  return std::string::npos;
}

// yaml-cpp passes bytes through: text that is not UTF-8 would reach the JSON, URDF and
// ROS messages written from the model.
void requireUtf8(const std::string& text, const std::string& source) {
  const std::size_t bad = firstInvalidUtf8(text);
  if (bad == std::string::npos) return;
  const std::size_t line_start = text.rfind('\n', bad) + 1;  // npos + 1 = 0 on the first line
  char byte[8];
  std::snprintf(byte, sizeof byte, "0x%02x", static_cast<unsigned char>(text[bad]));
  throw InputError(source + ":" + std::to_string(1 + std::count(text.begin(), text.begin() + bad, '\n')) + ":" +
                   std::to_string(bad - line_start + 1) + ": not valid UTF-8 (byte " + byte + "); a robot file is UTF-8 text");
}

RobotModel parseRobotYaml(const std::string& yaml_text, const std::string& source) {
  requireUtf8(yaml_text, source);
  YAML::Node root;
  try {
    root = YAML::Load(yaml_text);
  } catch (const YAML::ParserException& error) {
    throw InputError(source + ":" + std::to_string(error.mark.line + 1) + ":" + std::to_string(error.mark.column + 1) +
                     ": YAML syntax error: " + error.msg);
  }
  if (!root.IsMap()) {
    const std::string found = root.IsNull() ? "an empty document" : root.IsSequence() ? "a list" : "a single value";
    throw InputError(source + ": a robot file is a YAML mapping with fields name, output_variables, inputs, chains, "
                     "reference; found " + found);
  }
  const FieldReader top(root, source, "robot");
  top.rejectUnknownFields(kTopFields);
  RobotModel model;
  model.source = source;
  model.name = top.name("name");
  if (top.has("clearance")) {
    model.rod_clearance = top.number("clearance");
    if (model.rod_clearance < 0.0) top.fail("clearance", "must be a distance >= 0 m, got " + numberText(model.rod_clearance));
    if (model.rod_clearance > kMaxLength) {
      top.fail("clearance", "must be a distance of at most " + numberText(kMaxLength) + " m, got " + numberText(model.rod_clearance));
    }
  }
  model.output_variables = readOutputVariables(top);
  checkCounts(top, model.dof());
  ItemReaders readers;
  model.inputs = readInputs(top, readers);
  readChains(top, model, readers);
  readReference(top, model);
  checkMechanism(top, readers, model);
  return model;
}

}  // namespace

RobotModel parseRobotFile(const std::string& yaml_text, const std::string& source) {
  try {
    return parseRobotYaml(yaml_text, source);
  } catch (const YAML::Exception& error) {
    // Every check names its field; this net catches a node access none of them foresaw
    // (as fuzz_robot_file once found), so no robot file ends the program.
    throw InputError(source + ":" + std::to_string(error.mark.line + 1) + ": unexpected YAML structure: " + error.msg);
  }
}

RobotModel loadRobotFile(const std::string& path) { return parseRobotFile(readTextFile(path, "robot file"), path); }

}  // namespace maximal_workspace
