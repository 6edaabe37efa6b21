#include <cstdio>
#include <iostream>

#include "arguments.h"
#include "commands.h"
#include "maximal_workspace/kinematics/inverse_kinematics.h"
#include "maximal_workspace/kinematics/pose_analysis.h"
#include "maximal_workspace/kinematics/pose_classifier.h"
#include "maximal_workspace/model/robot_file.h"
#include "maximal_workspace/model/vector_text.h"

namespace maximal_workspace::cli {

namespace {

void printChainsAndInputs(const RobotModel& model) {
  std::cout << "chains (" << model.chainCount() << "):\n";
  for (const ChainPtr& chain : model.chains) {
    std::cout << "  " << chain->name() << "  " << chain->type() << "  input " << chain->input()
              << "  platform node " << vectorText(chain->platformNode()) << "\n      ";
    chain->describe(std::cout);
    std::cout << "\n";
    const ChainLimits& limits = chain->limits();
    const auto cone = [](const char* end, const std::optional<JointCone>& cone) {
      if (cone) std::cout << "  " << end << " cone axis " << vectorText(cone->axis) << " half-angle " << numberText(cone->half_angle) << " rad";
    };
    if (limits.fixed_end || limits.platform_end || limits.rod_radius > 0.0) {
      std::cout << "      limits:";
      cone("fixed_end", limits.fixed_end);
      cone("platform_end", limits.platform_end);
      if (limits.rod_radius > 0.0) std::cout << "  rod radius " << numberText(limits.rod_radius) << " m";
      std::cout << "\n";
    }
  }
  if (model.rod_clearance > 0.0) std::cout << "rods keep " << numberText(model.rod_clearance) << " m beyond their radii\n";
  std::cout << "inputs (" << model.inputCount() << "):\n";
  for (const Input& input : model.inputs) {
    std::cout << "  " << input.name << "  " << (input.kind == InputKind::Revolute ? "revolute" : "prismatic")
              << " (" << inputUnit(input.kind) << ")  chains";
    for (int c : input.chains) std::cout << " " << model.chains[c]->name();
    std::cout << (input.chains.size() > 1 ? " (couple)" : "") << "  limits ";
    if (input.limits) {
      std::cout << "[" << numberText((*input.limits)[0]) << ", " << numberText((*input.limits)[1]) << "]\n";
    } else {
      std::cout << "none\n";
    }
  }
}

void printReference(const RobotModel& model, const std::vector<WorkingMode>& modes) {
  const Pose& pose = model.reference.pose;
  std::cout << "reference pose: position " << vectorText(pose.position) << " m, orientation ZYZ "
            << vectorText(pose.euler_zyz) << " rad\n";
  const PoseAnalysis analysis = analysePose(model, pose, modes);
  std::printf("  %-8s %14s %16s %16s\n", "chain", "discriminant", "q(p)", "q(n)");
  for (int c = 0; c < model.chainCount(); ++c) {
    const ChainSolution& solution = analysis.ikp.chains[c];
    std::printf("  %-8s %14.6e %16.10f %16.10f\n", model.chains[c]->name().c_str(), solution.discriminant,
                solution.branch(Branch::Positive).q, solution.branch(Branch::Negative).q);
  }
  std::cout << "working mode at the reference: ";
  if (model.reference.inputs.empty()) {
    std::cout << "unknown (the robot file gives no reference inputs)\n";
  } else {
    std::cout << "inputs";
    for (int i = 0; i < model.inputCount(); ++i) {
      std::cout << " " << model.inputs[i].name << " = " << numberText(model.reference.inputs[i]) << " "
                << inputUnit(model.inputs[i].kind) << (i + 1 < model.inputCount() ? "," : ";");
    }
    const WorkingModeIdentification found = identifyWorkingMode(model, analysis.ikp, model.reference.inputs);
    if (!found.found) {
      std::cout << " unknown: " << found.reason << "\n";
    } else if (found.coupled) {
      std::cout << " working mode " << found.working_mode.name << " (chains " << found.uncoupled.name << ")\n";
    } else {
      std::cout << " chains " << found.uncoupled.name << ", not a working mode of the coupled robot\n";
    }
  }
  std::cout << "det J_DKP per working mode at the reference (twist form; measure: scale-free, in [-1, 1]):\n";
  std::printf("  %-8s %4s %16s %12s\n", "mode", "sign", "det", "measure");
  for (std::size_t m = 0; m < modes.size(); ++m) {
    const DkpSingularity& singularity = analysis.modes[m].singularity;
    const char* sign = singularity.det > 0 ? "+" : singularity.det < 0 ? "-" : "0";
    std::printf("  %-8s %4s %16.8e %12.6f\n", modes[m].name.c_str(), sign, singularity.det, singularity.measure);
  }
}

}  // namespace

int runInfo(const std::vector<std::string>& args) {
  const Arguments arguments(args, {"--robot"}, {"--uncoupled"});
  const RobotModel model = loadRobotFile(arguments.required("--robot"));
  const std::vector<WorkingMode> modes =
      arguments.flag("--uncoupled") ? uncoupledWorkingModes(model) : coupledWorkingModes(model);

  std::cout << "robot: " << model.name << "  (" << model.source << ")\n";
  std::cout << "output variables (" << model.dof() << " DOF):";
  for (OutputVariable variable : model.output_variables) std::cout << " " << outputVariableName(variable);
  std::cout << "\n";
  if (model.characteristic_length > 0.0) {
    std::cout << "characteristic length: " << numberText(model.characteristic_length)
              << " m (RMS platform-node distance from the TCP; scales rotations in the measure)\n";
  }
  printChainsAndInputs(model);
  std::cout << "working modes (" << modes.size()
            << (arguments.flag("--uncoupled") ? ", uncoupled: a letter per chain" : ": a letter per input") << "):";
  for (const WorkingMode& mode : modes) std::cout << " " << mode.name;
  std::cout << "\n";
  printReference(model, modes);
  std::cout << "batch kernels on this CPU: " << vectorKernelsInUse() << "\n";
  return 0;
}

}  // namespace maximal_workspace::cli
