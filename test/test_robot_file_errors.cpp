// Bad robot files: every mistake a user can make in a robot file must end in one
// InputError whose message names the file, the field (or chain) and the reason. Each case
// is one small textual mutation of the shipped config/delta_like.yaml, so the rest of the
// file stays valid and only the intended check can fire.

#include <algorithm>
#include <array>
#include <cmath>
#include <fstream>
#include <functional>
#include <sstream>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include <gtest/gtest.h>

#include "maximal_workspace/model/input_error.h"
#include "maximal_workspace/model/robot_file.h"
#include "test_support.h"

namespace maximal_workspace {
namespace {

const char* const kSource = "mutated_delta_like.yaml";

std::string readFixture(const std::string& relative) {
  std::ifstream in(test::sourcePath(relative), std::ios::binary);
  if (!in) throw std::runtime_error("cannot open fixture " + relative);
  std::ostringstream text;
  text << in.rdbuf();
  return text.str();
}

const std::string& deltaText() {
  static const std::string text = readFixture("config/delta_like.yaml");
  return text;
}

// --- Mutations. Each throws std::logic_error when its target is not in the text, so a
// change to the fixture cannot turn a case into a silent no-op.

using Mutation = std::function<std::string(const std::string&)>;

// Replaces `from`, which must occur exactly once.
Mutation replace(const std::string& from, const std::string& to) {
  return [from, to](const std::string& text) {
    const std::size_t at = text.find(from);
    if (at == std::string::npos || text.find(from, at + 1) != std::string::npos) {
      throw std::logic_error("mutation target must occur exactly once: " + from);
    }
    std::string result = text;
    return result.replace(at, from.size(), to);
  };
}

// Start and length (with its '\n') of the line `    <field>:` inside chain `chain`'s block.
std::pair<std::size_t, std::size_t> chainFieldLine(const std::string& text, const std::string& chain,
                                                   const std::string& field) {
  const std::size_t block = text.find("  - name: " + chain + "\n");
  if (block == std::string::npos) throw std::logic_error("no chain " + chain + " in the fixture");
  const std::size_t block_end = std::min(text.find("  - name:", block + 1), text.find("\nreference:", block));
  const std::size_t line = text.find("    " + field + ":", block);
  if (line == std::string::npos || line > block_end) throw std::logic_error("no field " + field + " in " + chain);
  return {line, text.find('\n', line) + 1 - line};
}

Mutation setChainField(const std::string& chain, const std::string& field, const std::string& value) {
  return [=](const std::string& text) {
    const auto [start, length] = chainFieldLine(text, chain, field);
    std::string result = text;
    return result.replace(start, length, "    " + field + ": " + value + "\n");
  };
}

Mutation removeChainField(const std::string& chain, const std::string& field) {
  return [=](const std::string& text) {
    const auto [start, length] = chainFieldLine(text, chain, field);
    std::string result = text;
    return result.erase(start, length);
  };
}

Mutation renameChainField(const std::string& chain, const std::string& field, const std::string& new_name) {
  return [=](const std::string& text) {
    const auto [start, length] = chainFieldLine(text, chain, field);
    std::string result = text;
    return result.replace(start + 4, field.size(), new_name);
  };
}

// Appends `lines` (each indented as a chain field, ending in '\n') to chain `chain`'s block:
// how the optional fields of issue 16 (joint_limits, rod_radius), absent from the fixture,
// are added.
Mutation appendToChain(const std::string& chain, const std::string& lines) {
  return [=](const std::string& text) {
    const std::size_t block = text.find("  - name: " + chain + "\n");
    const std::size_t reference = text.find("\nreference:", block);
    if (block == std::string::npos || reference == std::string::npos) {
      throw std::logic_error("no chain " + chain + " before the reference in the fixture");
    }
    const std::size_t block_end = std::min(text.find("  - name:", block + 1), reference + 1);
    std::string result = text;
    return result.insert(block_end, lines);
  };
}

// A joint_limits block on chain KC3a (a PSS slider along +z) with one cone `end: {body}`.
Mutation coneOnKC3a(const std::string& end, const std::string& body) {
  return appendToChain("KC3a", "    joint_limits:\n      " + end + ": {" + body + "}\n");
}

// Several mutations, one after the other.
Mutation all(std::vector<Mutation> mutations) {
  return [mutations](const std::string& text) {
    std::string result = text;
    for (const Mutation& mutate : mutations) result = mutate(result);
    return result;
  };
}

Mutation replaceWhole(const std::string& content) {
  return [content](const std::string&) { return content; };
}

struct BadFileCase {
  const char* name;  // gtest parameter name
  Mutation mutate;
  std::vector<std::string> expected;  // substrings of the message besides the source
  // Unique text on the line the message must start with (source:line:); null: not checked
  // here (RobotFileErrorLines checks a sample of the older cases).
  const char* line = nullptr;
};

void PrintTo(const BadFileCase& c, std::ostream* out) { *out << c.name; }

// Parses the mutated text; returns the InputError message, or fails the test.
std::string parseError(const std::string& text) {
  try {
    parseRobotFile(text, kSource);
  } catch (const InputError& error) {
    return error.what();
  }
  ADD_FAILURE() << "no InputError for:\n" << text;
  return {};
}

// 1-based number of the line where `needle` starts, found independently of yaml-cpp.
int lineOf(const std::string& text, const std::string& needle) {
  const std::size_t at = text.find(needle);
  if (at == std::string::npos) throw std::logic_error("not in text: " + needle);
  return 1 + static_cast<int>(std::count(text.begin(), text.begin() + at, '\n'));
}

class RobotFileErrorTest : public ::testing::TestWithParam<BadFileCase> {};

TEST_P(RobotFileErrorTest, ThrowsInputErrorNamingSourceFieldAndReason) {
  const BadFileCase& c = GetParam();
  std::string mutated;
  ASSERT_NO_THROW(mutated = c.mutate(deltaText()));
  ASSERT_NE(mutated, deltaText());
  const std::string message = parseError(mutated);
  EXPECT_NE(message.find(kSource), std::string::npos) << message;
  for (const std::string& part : c.expected) {
    EXPECT_NE(message.find(part), std::string::npos) << "expected '" << part << "' in: " << message;
  }
  if (c.line != nullptr) {
    const std::string location = std::string(kSource) + ":" + std::to_string(lineOf(mutated, c.line)) + ":";
    EXPECT_EQ(message.rfind(location, 0), 0u) << "expected the message to start with " << location << ": " << message;
  }
}

const std::string kTopListMessage = "YAML mapping";

INSTANTIATE_TEST_SUITE_P(
    Catalogue, RobotFileErrorTest,
    ::testing::Values(
        // Missing fields.
        BadFileCase{"MissingRodLength", removeChainField("KC2b", "rod_length"), {"KC2b", "'rod_length'", "missing"}},
        BadFileCase{"MissingTopName", replace("name: delta_like\n", ""), {"field 'name'", "missing"}},
        BadFileCase{"MissingReference",
                    replace("reference:\n  position: [0.15, 0.15, 0.75]\n  orientation: [0, 0, 0]\n"
                            "  inputs: {KC1: -2.1286070350306852, KC2: 0.6231, KC3: 0.4}\n",
                            ""),
                    {"'reference'", "missing"}},
        BadFileCase{"MissingChainType", removeChainField("KC3a", "type"), {"KC3a", "'type'", "missing"}},
        // Wrong types.
        BadFileCase{"ListForNumber", setChainField("KC3a", "rod_length", "[0.8, 0.9]"),
                    {"KC3a", "'rod_length'", "must be a number"}},
        BadFileCase{"TextForNumber", setChainField("KC1a", "crank_length", "long"),
                    {"KC1a", "'crank_length'", "must be a number"}},
        BadFileCase{"NumberForVector", setChainField("KC2a", "platform_node", "0.5"),
                    {"KC2a", "'platform_node'", "must be a list of 3"}},
        BadFileCase{"VectorOfTwo", setChainField("KC2a", "direction", "[0, 1]"),
                    {"KC2a", "'direction'", "must be a list of 3"}},
        BadFileCase{"TextForReferencePosition", replace("position: [0.15, 0.15, 0.75]", "position: here"),
                    {"'position'", "must be a list of 3"}},
        // Non-finite numbers.
        BadFileCase{"NanLength", setChainField("KC3b", "rod_length", ".nan"), {"KC3b", "'rod_length'", "finite"}},
        BadFileCase{"InfLength", setChainField("KC1b", "crank_length", ".inf"), {"KC1b", "'crank_length'", "finite"}},
        BadFileCase{"NanInVector", setChainField("KC2b", "fixed_node", "[0.0, .nan, 0.0]"),
                    {"KC2b", "'fixed_node'", "finite"}},
        BadFileCase{"InfInVector", setChainField("KC3a", "platform_node", "[0.15, -.inf, 0.05]"),
                    {"KC3a", "'platform_node'", "finite"}},
        BadFileCase{"InfInReferenceInput", replace("KC3: 0.4}", "KC3: .inf}"), {"'KC3'", "finite"}},
        // Lengths must be positive.
        BadFileCase{"ZeroRodLength", setChainField("KC2a", "rod_length", "0"), {"KC2a", "'rod_length'", "> 0"}},
        BadFileCase{"NegativeRodLength", setChainField("KC1a", "rod_length", "-0.65"),
                    {"KC1a", "'rod_length'", "> 0"}},
        BadFileCase{"ZeroCrankLength", setChainField("KC1b", "crank_length", "0.0"),
                    {"KC1b", "'crank_length'", "> 0"}},
        BadFileCase{"NegativeCrankLength", setChainField("KC1a", "crank_length", "-0.7"),
                    {"KC1a", "'crank_length'", "> 0"}},
        // Directions must be non-zero.
        BadFileCase{"ZeroAxis", setChainField("KC1a", "axis", "[0, 0, 0]"), {"KC1a", "'axis'", "non-zero"}},
        BadFileCase{"ZeroSliderDirection", setChainField("KC3b", "direction", "[0.0, 0.0, 0.0]"),
                    {"KC3b", "'direction'", "non-zero"}},
        // Names.
        BadFileCase{"DuplicateChainName", replace("  - name: KC2b\n", "  - name: KC2a\n"), {"KC2a", "twice"}},
        BadFileCase{"DuplicateInputName", replace("  - name: KC2\n", "  - name: KC1\n"), {"KC1", "twice"}},
        BadFileCase{"UnknownChainType", setChainField("KC3a", "type", "UPS"),
                    {"KC3a", "'type'", "unknown chain type 'UPS'"}},
        BadFileCase{"UndeclaredInput", setChainField("KC3b", "input", "KC9"), {"KC3b", "KC9", "not declared"}},
        // KC4 also gets a reference value, so only the missing chain is wrong.
        BadFileCase{"InputDrivenByNoChain",
                    all({replace("  - name: KC3\n", "  - name: KC3\n  - name: KC4\n"),
                         replace("KC3: 0.4}", "KC3: 0.4, KC4: 0.0}")}),
                    {"KC4", "no chain"}},
        // Couples must be parallelograms: the second chain is the first moved by the
        // platform-node offset, with the same direction, lengths and axis.
        BadFileCase{"CoupleFixedNodeMoved", setChainField("KC2b", "fixed_node", "[0.0, 0.0, 0.1]"),
                    {"KC2a", "KC2b", "parallel translates"}},
        BadFileCase{"CoupleDirectionChanged", setChainField("KC3b", "direction", "[0, 0.1, 1]"),
                    {"KC3a", "KC3b", "parallel translates"}},
        BadFileCase{"CoupleRodLengthChanged", setChainField("KC1b", "rod_length", "0.66"),
                    {"KC1a", "KC1b", "parallel translates"}},
        // Unknown fields and output variables.
        BadFileCase{"MisspeltField", renameChainField("KC2a", "rod_length", "rod_lenght"),
                    {"KC2a", "'rod_lenght'", "unknown"}},
        // An item without its name (found by fuzz_robot_file: it used to end the program).
        BadFileCase{"InputWithoutName", replace("  - name: KC2\n", "  - nam: KC2\n"), {"inputs[1]", "'nam'", "unknown"}},
        BadFileCase{"UnknownTopField", replace("name: delta_like\n", "name: delta_like\nmass: 3\n"),
                    {"'mass'", "unknown"}},
        BadFileCase{"UnknownOutputVariable", replace("[x, y, z, phi, theta, psi]", "[x, y, z, phi, theta, chi]"),
                    {"output_variables", "'chi'", "unknown"}},
        BadFileCase{"DuplicatedOutputVariable", replace("[x, y, z, phi, theta, psi]", "[x, y, z, phi, theta, theta]"),
                    {"output_variables", "'theta'", "twice"}},
        BadFileCase{"ThetaAlone", replace("[x, y, z, phi, theta, psi]", "[x, y, z, theta]"),
                    {"output_variables", "must be"}},
        BadFileCase{"ChainCountNotDof", replace("[x, y, z, phi, theta, psi]", "[x, y, z]"),
                    {"'chains'", "6 chains for 3 output variables"}},
        // Not a robot file at all.
        BadFileCase{"EmptyFile", replaceWhole(""), {kTopListMessage}},
        BadFileCase{"TopLevelList", replaceWhole("- name: delta_like\n- chains: []\n"), {kTopListMessage}},
        // Reference configuration.
        BadFileCase{"ReferenceNotAssembled", replace("position: [0.15, 0.15, 0.75]", "position: [5, 5, 5]"),
                    {"reference", "'position'", "cannot be assembled"}},
        BadFileCase{"ReferenceInputOutsideLimits", replace("  - name: KC2\n", "  - name: KC2\n    limits: [0.0, 0.5]\n"),
                    {"'KC2'", "outside the input's limits"}},
        BadFileCase{"LimitsReversed", replace("  - name: KC2\n", "  - name: KC2\n    limits: [1.0, 0.5]\n"),
                    {"inputs[1]", "'limits'", "min must be below max"}},
        BadFileCase{"LimitsEqual", replace("  - name: KC3\n", "  - name: KC3\n    limits: [0.4, 0.4]\n"),
                    {"inputs[2]", "'limits'", "min must be below max"}},
        // Limits (issue 16). Input ranges: a revolute one reversed, or over one turn.
        BadFileCase{"RevoluteLimitsReversed", replace("  - name: KC1\n", "  - name: KC1\n    limits: [-1.6, -2.6]\n"),
                    {"inputs[0] (KC1)", "'limits'", "min must be below max"},
                    "    limits: [-1.6, -2.6]"},
        BadFileCase{"RevoluteRangeOverOneTurn", replace("  - name: KC1\n", "  - name: KC1\n    limits: [-4.0, 2.5]\n"),
                    {"inputs[0] (KC1)", "'limits'", "a revolute range spans at most one turn (max - min <= 2 pi)"},
                    "    limits: [-4.0, 2.5]"},
        // [2.5, 4.0] crosses pi; the reference -2.1286 is 4.1546 one turn up: outside. (The
        // same range up to 4.2 holds it: RobotFileLimits.RevoluteRangeMayCrossPi.)
        BadFileCase{"ReferenceInputOutsideRangeAcrossPi",
                    replace("  - name: KC1\n", "  - name: KC1\n    limits: [2.5, 4.0]\n"),
                    {"reference.inputs", "'KC1'", "value -2.12860703503 is outside the input's limits"},
                    "  inputs: {KC1:"},
        // Cones: the half-angle is in (0, pi], the axis non-zero, only axis and half_angle.
        BadFileCase{"NegativeHalfAngle", coneOnKC3a("fixed_end", "axis: [0, 0, 1], half_angle: -0.5"),
                    {"chains[4] (KC3a).joint_limits.fixed_end", "'half_angle'", "must be an angle in (0, pi] rad, got -0.5"},
                    "      fixed_end: {axis: [0, 0, 1], half_angle: -0.5}"},
        BadFileCase{"ZeroHalfAngle", coneOnKC3a("fixed_end", "axis: [0, 0, 1], half_angle: 0"),
                    {"chains[4] (KC3a).joint_limits.fixed_end", "'half_angle'", "must be an angle in (0, pi] rad, got 0"},
                    "      fixed_end: {axis: [0, 0, 1], half_angle: 0}"},
        BadFileCase{"HalfAngleOverPi", coneOnKC3a("platform_end", "axis: [0, 0, -1], half_angle: 3.2"),
                    {"chains[4] (KC3a).joint_limits.platform_end", "'half_angle'", "must be an angle in (0, pi] rad, got 3.2"},
                    "      platform_end: {axis: [0, 0, -1], half_angle: 3.2}"},
        BadFileCase{"ZeroConeAxis", coneOnKC3a("fixed_end", "axis: [0, 0, 0], half_angle: 1.2"),
                    {"chains[4] (KC3a).joint_limits.fixed_end", "'axis'",
                     "must be a non-zero direction of finite length, got (0, 0, 0)"},
                    "      fixed_end: {axis: [0, 0, 0], half_angle: 1.2}"},
        BadFileCase{"TextInConeAxis", coneOnKC3a("fixed_end", "axis: [0, up, 1], half_angle: 1.2"),
                    {"chains[4] (KC3a).joint_limits.fixed_end", "'axis' element 1", "must be a number, got 'up'"},
                    "      fixed_end: {axis: [0, up, 1], half_angle: 1.2}"},
        BadFileCase{"UnknownJointLimitsField", coneOnKC3a("fixedend", "axis: [0, 0, 1], half_angle: 1.2"),
                    {"chains[4] (KC3a).joint_limits", "'fixedend'", "unknown here (expected: fixed_end, platform_end)"},
                    "      fixedend:"},
        BadFileCase{"UnknownConeField", coneOnKC3a("fixed_end", "axis: [0, 0, 1], half_angle: 1.2, angle: 1.0"),
                    {"chains[4] (KC3a).joint_limits.fixed_end", "'angle'", "unknown here (expected: axis, half_angle)"},
                    "      fixed_end: {axis: [0, 0, 1], half_angle: 1.2, angle: 1.0}"},
        // At the reference (inputs 0.4 for KC3) KC3a's slider node is a = (1, 0, 0) + 0.4 z =
        // (1, 0, 0.4) and its platform node p = TCP (0.15, 0.15, 0.75) + (0.15, -0.15, 0.05) =
        // (0.3, 0, 0.8); the rod a -> p = (-0.7, 0, 0.4) makes acos(0.4 / sqrt(0.65)) =
        // 1.0517 rad with +z: a fixed_end cone of 1.0 about +z is broken (one of 1.1 holds:
        // RobotFileLimits.ReferenceJustInsideAConeLoads).
        BadFileCase{"ReferenceOutsideCone", coneOnKC3a("fixed_end", "axis: [0, 0, 1], half_angle: 1.0"),
                    {"reference", "'inputs'", "the reference configuration breaks a limit", "chain 'KC3a'",
                     "leaves its fixed_end cone (angle 1.05165", "> half_angle 1)"},
                    "  inputs: {KC1:"},
        // Rod radii are lengths > 0; the clearance a distance >= 0.
        BadFileCase{"ZeroRodRadius", appendToChain("KC2a", "    rod_radius: 0\n"),
                    {"chains[2] (KC2a)", "'rod_radius'", "must be a length > 0 m, got 0"}, "    rod_radius: 0\n"},
        BadFileCase{"NegativeRodRadius", appendToChain("KC2a", "    rod_radius: -0.01\n"),
                    {"chains[2] (KC2a)", "'rod_radius'", "must be a length > 0 m, got -0.01"}, "    rod_radius: -0.01"},
        BadFileCase{"NegativeClearance", replace("name: delta_like\n", "name: delta_like\nclearance: -0.001\n"),
                    {"robot", "'clearance'", "must be a distance >= 0 m, got -0.001"}, "clearance: -0.001"},
        // Issue 18. Every normalised vector: finite components whose norm overflows used to
        // normalise to (0, 0, 0) and load; one whose norm underflows to a subnormal
        // normalises inexactly.
        BadFileCase{"HugeSliderDirection", setChainField("KC2a", "direction", "[0, 1e300, 0]"),
                    {"chains[2] (KC2a)", "'direction'", "must be a non-zero direction of finite length, got (0, 1e+300, 0)"},
                    "    direction: [0, 1e300, 0]"},
        BadFileCase{"HugeAxis", setChainField("KC1b", "axis", "[1e300, -1e300, 0]"),
                    {"chains[1] (KC1b)", "'axis'", "must be a non-zero direction of finite length, got (1e+300, -1e+300, 0)"},
                    "    axis: [1e300, -1e300, 0]"},
        BadFileCase{"HugeCrankZero", appendToChain("KC1a", "    crank_zero: [1e300, 1e300, 0]\n"),
                    {"chains[0] (KC1a)", "'crank_zero'", "must be a non-zero direction of finite length, got (1e+300, 1e+300, 0)"},
                    "    crank_zero: [1e300, 1e300, 0]"},
        BadFileCase{"HugeConeAxis", coneOnKC3a("platform_end", "axis: [0, 0, -1e300], half_angle: 1.2"),
                    {"chains[4] (KC3a).joint_limits.platform_end", "'axis'",
                     "must be a non-zero direction of finite length, got (0, 0, -1e+300)"},
                    "      platform_end: {axis: [0, 0, -1e300], half_angle: 1.2}"},
        BadFileCase{"SubnormalSliderDirection", setChainField("KC3b", "direction", "[0, 0, 1e-160]"),
                    {"chains[5] (KC3b)", "'direction'", "must be a non-zero direction of finite length, got (0, 0, 1e-160)"},
                    "    direction: [0, 0, 1e-160]"},
        // Issue 28. Lengths and points beyond 1e24 m: a rod of 1e200 m loaded, its square
        // overflowed, and NaN inputs and determinants passed as a workspace.
        BadFileCase{"HugeRodLength", setChainField("KC2a", "rod_length", "1e200"),
                    {"chains[2] (KC2a)", "'rod_length'", "must be a length of at most 1e+24 m, got 1e+200"},
                    "    rod_length: 1e200"},
        BadFileCase{"HugeCrankLength", setChainField("KC1b", "crank_length", "3e307"),
                    {"chains[1] (KC1b)", "'crank_length'", "must be a length of at most 1e+24 m, got 3e+307"},
                    "    crank_length: 3e307"},
        BadFileCase{"HugeFixedNode", setChainField("KC3b", "fixed_node", "[0.5, 1e154, 0.3]"),
                    {"chains[5] (KC3b)", "'fixed_node'", "must be a point within 1e+24 m of the origin along each axis, got (0.5, 1e+154, 0.3)"},
                    "    fixed_node: [0.5, 1e154, 0.3]"},
        BadFileCase{"HugePlatformNode", setChainField("KC3a", "platform_node", "[-2e30, 0, 0]"),
                    {"chains[4] (KC3a)", "'platform_node'", "must be a point within 1e+24 m of the origin along each axis"},
                    "    platform_node: [-2e30, 0, 0]"},
        BadFileCase{"HugeReferencePosition", replace("position: [0.15, 0.15, 0.75]", "position: [0.15, 1e200, 0.75]"),
                    {"reference", "'position'", "must be a point within 1e+24 m"}, "  position: [0.15, 1e200, 0.75]"},
        BadFileCase{"HugeClearance", replace("name: delta_like\n", "name: delta_like\nclearance: 1e100\n"),
                    {"robot", "'clearance'", "must be a distance of at most 1e+24 m, got 1e+100"}, "clearance: 1e100"},
        BadFileCase{"HugeRodRadius", appendToChain("KC2a", "    rod_radius: 1e30\n"),
                    {"chains[2] (KC2a)", "'rod_radius'", "must be a length of at most 1e+24 m, got 1e+30"},
                    "    rod_radius: 1e30"},
        // Issue 28: a file that is not a robot file had its first line echoed as a key (a
        // password file's hash): only a key that could be a field name is shown.
        BadFileCase{"FirstLineOfAnotherFile", replace("name: delta_like\n", "root:$y$j9T$secret:19000:0:99999:7:::\nname: delta_like\n"),
                    {"robot", "a key that is no field name (36 bytes): unknown here"}, "root:$y$j9T$secret"},
        // A key given twice in any mapping; yaml-cpp used to keep both and lookups the first.
        // (RobotFileErrorLines.RepeatedFieldNamesBothLines: a chain's field.)
        BadFileCase{"RepeatedTopField", replace("name: delta_like\n", "name: delta_like\nname: other\n"),
                    {"robot", "field 'name'", "given twice (lines "}, "name: other"},
        BadFileCase{"RepeatedReferenceInput", replace("KC3: 0.4}", "KC3: 0.4, KC3: 99}"),
                    {"reference.inputs", "field 'KC3'", "given twice on this line"}, "  inputs: {KC1:"},
        BadFileCase{"RepeatedConeField", coneOnKC3a("fixed_end", "axis: [0, 0, 1], half_angle: 1.2, half_angle: 0.1"),
                    {"chains[4] (KC3a).joint_limits.fixed_end", "field 'half_angle'", "given twice on this line"},
                    "      fixed_end: {axis: [0, 0, 1], half_angle: 1.2, half_angle: 0.1}"},
        // Names: letters, digits, _ - . only; anything else is shown escaped.
        BadFileCase{"RobotNameWithSpace", replace("name: delta_like\n", "name: delta like\n"),
                    {"robot", "field 'name'", "'delta like' has ' ', not allowed in a name (letters, digits, _ - .)"},
                    "name: delta like"},
        BadFileCase{"ChainNameWithMarkup", replace("  - name: KC1a\n", "  - name: KC<1a\n"),
                    {"chains[0] (KC<1a)", "field 'name'", "'KC<1a' has '<', not allowed in a name"}, "  - name: KC<1a"},
        BadFileCase{"InputNameWithQuote", replace("  - name: KC2\n", "  - name: KC\"2\n"),
                    {"inputs[1] (KC\"2)", "field 'name'", "'KC\"2' has '\"', not allowed in a name"}, "  - name: KC\"2"},
        BadFileCase{"InputNameBeyondAscii", replace("  - name: KC1\n", "  - name: KC\xc3\xa9" "1\n"),
                    {"inputs[0] (KC\\xc3\\xa91)", "'KC\\xc3\\xa91' has '\\xc3\\xa9', not allowed in a name"},
                    "  - name: KC\xc3\xa9"},
        BadFileCase{"InputNameWithTab", replace("  - name: KC3\n", "  - name: \"KC\\t3\"\n"),
                    {"inputs[2] (KC\\x093)", "'KC\\x093' has '\\x09', not allowed in a name"}, "  - name: \"KC\\t3\""},
        // Text that is not UTF-8 anywhere in the file (RobotFileText: every kind of bad sequence).
        BadFileCase{"NameNotUtf8", replace("name: delta_like\n", "name: delta_l\xe9ke\n"),
                    {":14: not valid UTF-8 (byte 0xe9); a robot file is UTF-8 text"}, "name: delta_l"},
        // Counts before items: a chain or input too many is refused before any item is read,
        // so here before the extra chain's unknown type or the extra inputs' missing
        // reference values.
        BadFileCase{"ChainCountBeforeTheChains", replace("reference:\n", "  - name: KC4a\n    type: UPS\nreference:\n"),
                    {"'chains'", "7 chains for 6 output variables"}, "  - name: KC1a"},
        BadFileCase{"MoreInputsThanChains",
                    replace("  - name: KC3\n", "  - name: KC3\n  - name: A\n  - name: B\n  - name: C\n  - name: D\n"),
                    {"'inputs'", "each input drives at least one chain: 7 inputs for 6 chains"}, "  - name: KC1\n"}),
    [](const ::testing::TestParamInfo<BadFileCase>& info) { return std::string(info.param.name); });

struct LineCase {
  Mutation mutate;
  std::string line_text;  // unique text on the line the message must point at
};

TEST(RobotFileErrorLines, MessageCarriesTheLineOfTheBadField) {
  const std::vector<LineCase> cases = {
      {setChainField("KC3a", "rod_length", ".nan"), "    rod_length: .nan"},
      {setChainField("KC2b", "direction", "[0, 0, 0]"), "    direction: [0, 0, 0]"},
      {setChainField("KC1b", "crank_length", "-1"), "    crank_length: -1"},
      {renameChainField("KC3b", "fixed_node", "fixed_nod"), "    fixed_nod:"},
      // Checks across fields point at the item concerned.
      {replace("position: [0.15, 0.15, 0.75]", "position: [5, 5, 5]"), "  position: [5, 5, 5]"},
      {setChainField("KC2b", "fixed_node", "[0.0, 0.0, 0.1]"), "    input: KC2\n    fixed_node: [0.0, 0.0, 0.1]"},
      {all({replace("  - name: KC3\n", "  - name: KC3\n  - name: KC4\n"), replace("KC3: 0.4}", "KC3: 0.4, KC4: 0.0}")}),
       "  - name: KC4"},
      {replace("  - name: KC2\n", "  - name: KC2\n    limits: [1.0, 0.5]\n"), "    limits: [1.0, 0.5]"},
      {replace("name: delta_like\n", "name: delta: like\n"), "name: delta: like"},  // YAML syntax error
  };
  for (const LineCase& c : cases) {
    const std::string mutated = c.mutate(deltaText());
    const std::string message = parseError(mutated);
    const std::string location = std::string(kSource) + ":" + std::to_string(lineOf(mutated, c.line_text)) + ":";
    EXPECT_EQ(message.rfind(location, 0), 0u) << "expected the message to start with " << location << ": " << message;
  }
}

TEST(RobotFileErrorLines, SyntaxErrorIsReportedAsSuch) {
  const std::string message = parseError(replace("name: delta_like\n", "name: delta: like\n")(deltaText()));
  EXPECT_NE(message.find("syntax error"), std::string::npos) << message;
}

// Issue 18: a chain's field given twice; the message points at the second and names both.
TEST(RobotFileErrorLines, RepeatedFieldNamesBothLines) {
  const std::string mutated = appendToChain("KC2b", "    rod_length: 0.9\n")(deltaText());
  const std::string first = std::to_string(lineOf(mutated, "    rod_length: 0.86278248127787116\n    platform_node: [-0.15"));
  const std::string second = std::to_string(lineOf(mutated, "    rod_length: 0.9\n"));
  EXPECT_EQ(parseError(mutated), std::string(kSource) + ":" + second +
                                     ": chains[3] (KC2b): field 'rod_length': given twice (lines " + first + " and " +
                                     second + ")");
}

// Issue 18: the byte sequences UTF-8 forbids (RFC 3629) are refused wherever they are (here
// at column 3 of the first comment, or cut short by the end of the file); well-formed
// characters of 2, 3 and 4 bytes load.
TEST(RobotFileText, OnlyWellFormedUtf8Loads) {
  const std::vector<std::pair<std::string, std::string>> bad = {
      {"\x80", "0x80"},              // a continuation byte alone
      {"\xc0\xaf", "0xc0"},          // an overlong '/'
      {"\xe2\x82", "0xe2"},          // a sequence cut short
      {"\xed\xa0\x80", "0xed"},      // a surrogate
      {"\xf4\x90\x80\x80", "0xf4"},  // beyond U+10FFFF
      {"\xff", "0xff"}};
  for (const auto& [bytes, byte] : bad) {
    const std::string message = parseError(replace("# The chapter's", "# " + bytes + "The chapter's")(deltaText()));
    EXPECT_EQ(message.rfind(std::string(kSource) + ":1:3: not valid UTF-8 (byte " + byte + ")", 0), 0u) << message;
  }
  const std::string cut = parseError(deltaText() + "#\xf0\x9f\x98");
  EXPECT_NE(cut.find("not valid UTF-8 (byte 0xf0)"), std::string::npos) << cut;
  EXPECT_NO_THROW(parseRobotFile(
      replace("# The chapter's", "# \xc3\xa9 \xe2\x82\xac \xf0\x9f\x98\x80 The chapter's")(deltaText()), kSource));
}

// Issue 18: names of every allowed character, a digit first included, load as written.
TEST(RobotFileNames, LettersDigitsUnderscoreHyphenAndDotLoad) {
  std::string text = replace("name: delta_like\n", "name: 2nd.delta-like_B\n")(deltaText());
  // The input KC2 renamed wherever it is named: its item, its chains' names and input
  // fields, the reference inputs.
  for (std::size_t at; (at = text.find("KC2")) != std::string::npos;) text.replace(at, 3, "kc-2.x_Y");
  RobotModel model;
  ASSERT_NO_THROW(model = parseRobotFile(text, kSource));
  EXPECT_EQ(model.name, "2nd.delta-like_B");
  EXPECT_EQ(model.inputs[1].name, "kc-2.x_Y");
  EXPECT_EQ(model.chains[2]->name(), "kc-2.x_Ya");
  EXPECT_EQ(model.chains[3]->input(), "kc-2.x_Y");
}

// A name of 1 MB is quoted cut (its start and its size), not echoed whole.
TEST(RobotFileNames, AHugeBadNameIsQuotedCut) {
  const std::string text = replace("name: delta_like\n", "name: " + std::string(1 << 20, 'x') + "<\n")(deltaText());
  try {
    parseRobotFile(text, kSource);
    ADD_FAILURE() << "a name with '<' loaded";
  } catch (const InputError& error) {
    const std::string message = error.what();
    EXPECT_LT(message.size(), 400u) << message.substr(0, 400);
    EXPECT_NE(message.find("xxxx... (1048577 bytes)"), std::string::npos) << message.substr(0, 400);
    EXPECT_NE(message.find("has '<'"), std::string::npos) << message.substr(0, 400);
  }
}

// Issue 18: a direction is refused only where it cannot be normalised; one far from unit
// length either way loads as its unit vector.
TEST(RobotFileDirections, NormalisableDirectionsLoadAsUnitVectors) {
  for (const char* direction : {"[0, 0, 1e-100]", "[0, 0, 1e100]"}) {
    const std::string text =
        all({setChainField("KC3a", "direction", direction), setChainField("KC3b", "direction", direction)})(deltaText());
    RobotModel model;
    ASSERT_NO_THROW(model = parseRobotFile(text, kSource)) << direction;
    EXPECT_EQ(model.chains[4]->intermediateNodeRate(0.0), Eigen::Vector3d(0, 0, 1)) << direction;
  }
}

void expectPathError(const std::string& path, const std::string& reason) {
  try {
    loadRobotFile(path);
    ADD_FAILURE() << "no InputError for " << path;
  } catch (const InputError& error) {
    const std::string message = error.what();
    EXPECT_NE(message.find(path), std::string::npos) << message;
    EXPECT_NE(message.find(reason), std::string::npos) << message;
  }
}

TEST(RobotFilePaths, NonexistentPathNamesThePath) {
  expectPathError(test::sourcePath("config/no_such_robot.yaml"), "cannot read");
}

TEST(RobotFilePaths, DirectoryPathNamesThePath) { expectPathError(test::sourcePath("config"), "directory"); }

// The fuzz seeds of issue 18's inputs must stay refused for their reason, or the fuzzer
// would start from another rejection than the one each stands for.
TEST(RobotFilePaths, Issue18FuzzSeedsAreRefusedForTheirReason) {
  const std::vector<std::pair<const char*, const char*>> seeds = {
      {"direction-overflow.yaml", "'axis': must be a non-zero direction of finite length"},
      {"repeated-key.yaml", "'rod_length': given twice"},
      {"name-characters.yaml", "not allowed in a name"},
      {"not-utf8.yaml", "not valid UTF-8"},
      {"chain-count.yaml", "3 chains for 2 output variables"}};
  for (const auto& [seed, reason] : seeds) {
    expectPathError(test::sourcePath(std::string("test/fuzz/corpus/robot_file/") + seed), reason);
  }
}

// The catalogue is only meaningful if the unmutated files are accepted.
TEST(RobotFilePaths, ShippedFilesLoad) {
  RobotModel delta, five_bar;
  ASSERT_NO_THROW(delta = loadRobotFile(test::sourcePath("config/delta_like.yaml")));
  ASSERT_NO_THROW(five_bar = loadRobotFile(test::sourcePath("config/five_bar.yaml")));
  EXPECT_EQ(delta.chainCount(), 6);
  EXPECT_EQ(delta.inputCount(), 3);
  EXPECT_EQ(five_bar.chainCount(), 2);
  EXPECT_EQ(five_bar.inputCount(), 2);
  EXPECT_NO_THROW(parseRobotFile(deltaText(), kSource));
}

// --- The limit fields of issue 16 when they are right: read into the model as written.

TEST(RobotFileLimits, EveryNewFieldLoadsIntoTheModel) {
  const std::string text = all({
      replace("name: delta_like\n", "name: delta_like\nclearance: 0.002\n"),
      replace("  - name: KC1\n", "  - name: KC1\n    limits: [-2.6, -1.6]\n"),
      replace("  - name: KC2\n", "  - name: KC2\n    limits: [0.2, 1.0]\n"),
      replace("  - name: KC3\n", "  - name: KC3\n    limits: [0.0, 0.8]\n"),
      appendToChain("KC1a", "    joint_limits:\n      fixed_end: {axis: [-0.6931, 0.6931, 0.1980], half_angle: 1.0}\n"
                            "      platform_end: {axis: [-0.7658, -0.5240, -0.3728], half_angle: 0.9}\n"
                            "    rod_radius: 0.01\n"),
      appendToChain("KC2b", "    rod_radius: 0.012\n"),
      // Unnormalised on purpose; the reference's 1.0517 rad (see ReferenceOutsideCone) is inside.
      coneOnKC3a("fixed_end", "axis: [0, 0, 2], half_angle: 1.2"),
      appendToChain("KC3b", "    joint_limits:\n      platform_end:\n        axis: [0, 0, -1]\n"
                            "        half_angle: 3.141592653589793\n"),
  })(deltaText());
  RobotModel model;
  ASSERT_NO_THROW(model = parseRobotFile(text, kSource));
  EXPECT_EQ(model.rod_clearance, 0.002);
  ASSERT_EQ(model.inputCount(), 3);
  const std::array<double, 2> kc1{-2.6, -1.6}, kc2{0.2, 1.0}, kc3{0.0, 0.8};
  EXPECT_EQ(model.inputs[0].limits, kc1);
  EXPECT_EQ(model.inputs[1].limits, kc2);
  EXPECT_EQ(model.inputs[2].limits, kc3);

  const auto limits = [&model](const char* chain) -> const ChainLimits& {
    const int index = model.chainIndex(chain);
    if (index < 0) throw std::logic_error(std::string("no chain ") + chain);
    return model.chains[index]->limits();
  };
  const ChainLimits& kc1a = limits("KC1a");
  ASSERT_TRUE(kc1a.fixed_end && kc1a.platform_end);
  // Axes are normalised on load.
  EXPECT_LT((kc1a.fixed_end->axis - Eigen::Vector3d(-0.6931, 0.6931, 0.1980).normalized()).norm(), 1e-15);
  EXPECT_EQ(kc1a.fixed_end->half_angle, 1.0);
  EXPECT_LT((kc1a.platform_end->axis - Eigen::Vector3d(-0.7658, -0.5240, -0.3728).normalized()).norm(), 1e-15);
  EXPECT_EQ(kc1a.platform_end->half_angle, 0.9);
  EXPECT_EQ(kc1a.rod_radius, 0.01);
  const ChainLimits& kc3a = limits("KC3a");
  ASSERT_TRUE(kc3a.fixed_end);
  EXPECT_FALSE(kc3a.platform_end);
  EXPECT_EQ(kc3a.fixed_end->axis, Eigen::Vector3d(0, 0, 1));
  EXPECT_EQ(kc3a.fixed_end->half_angle, 1.2);
  EXPECT_EQ(kc3a.rod_radius, 0.0);
  const ChainLimits& kc3b = limits("KC3b");
  ASSERT_TRUE(kc3b.platform_end);
  EXPECT_FALSE(kc3b.fixed_end);
  EXPECT_EQ(kc3b.platform_end->axis, Eigen::Vector3d(0, 0, -1));
  EXPECT_EQ(kc3b.platform_end->half_angle, M_PI);  // the largest half-angle allowed
  EXPECT_EQ(limits("KC2b").rod_radius, 0.012);
  // A chain the file gives no limits keeps none.
  const ChainLimits& kc2a = limits("KC2a");
  EXPECT_FALSE(kc2a.fixed_end || kc2a.platform_end);
  EXPECT_EQ(kc2a.rod_radius, 0.0);
  // Without the fields nothing is limited.
  const RobotModel plain = parseRobotFile(deltaText(), kSource);
  EXPECT_EQ(plain.rod_clearance, 0.0);
  for (const Input& input : plain.inputs) EXPECT_FALSE(input.limits) << input.name;
}

// Revolute ranges are angle intervals: [2.5, 4.2] crosses pi and holds the reference
// -2.1286 (4.1546 one turn up); [-4.0, -2.0] crosses -pi and holds it as written.
TEST(RobotFileLimits, RevoluteRangeMayCrossPi) {
  for (const char* range : {"[2.5, 4.2]", "[-4.0, -2.0]"}) {
    const std::string text =
        replace("  - name: KC1\n", std::string("  - name: KC1\n    limits: ") + range + "\n")(deltaText());
    RobotModel model;
    ASSERT_NO_THROW(model = parseRobotFile(text, kSource)) << range;
    ASSERT_TRUE(model.inputs[0].limits) << range;
  }
  const RobotModel model =
      parseRobotFile(replace("  - name: KC1\n", "  - name: KC1\n    limits: [2.5, 4.2]\n")(deltaText()), kSource);
  const std::array<double, 2> written{2.5, 4.2};
  EXPECT_EQ(model.inputs[0].limits, written);  // kept as written, not wrapped into (-pi, pi]
}

// The boundary of ReferenceOutsideCone: the rod's 1.0517 rad at the reference is inside 1.1.
TEST(RobotFileLimits, ReferenceJustInsideAConeLoads) {
  EXPECT_NO_THROW(parseRobotFile(coneOnKC3a("fixed_end", "axis: [0, 0, 1], half_angle: 1.1")(deltaText()), kSource));
}

// The robot-file fuzz target's seed with every limit field must stay a valid robot file,
// or the fuzzer would start from a rejection.
TEST(RobotFileLimits, FuzzSeedWithEveryLimitLoads) {
  RobotModel model;
  ASSERT_NO_THROW(model = loadRobotFile(test::sourcePath("test/fuzz/corpus/robot_file/every_limit.yaml")));
  EXPECT_GT(model.rod_clearance, 0.0);
  for (const Input& input : model.inputs) EXPECT_TRUE(input.limits) << input.name;
  for (const ChainPtr& chain : model.chains) {
    EXPECT_GT(chain->limits().rod_radius, 0.0) << chain->name();
    EXPECT_TRUE(chain->limits().fixed_end) << chain->name();
  }
}

}  // namespace
}  // namespace maximal_workspace
