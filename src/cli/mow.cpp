// mow: the maximal-workspace command-line tool. No ROS master needed.

#include <exception>
#include <iostream>
#include <string>
#include <vector>

#include "commands.h"
#include "maximal_workspace/model/input_error.h"
#include "maximal_workspace/workspace/cancellation.h"

namespace {

const char* const kUsage =
    "usage: mow <command> [options]\n"
    "\n"
    "commands:\n"
    "  info --robot FILE [--uncoupled]\n"
    "      chains, inputs, working modes; at the reference pose: discriminants, the working\n"
    "      mode the robot is in, and the sign of det J_DKP of every working mode\n"
    "  eval --robot FILE --poses FILE.csv [--out FILE.csv] [--uncoupled]\n"
    "       [--step S | --steps a,b,c] [workspace options: --cache, --margin, ...]\n"
    "      per pose: inside flag, chain discriminants, and per working mode the inputs,\n"
    "      det J_DKP (twist form) and the normalised singularity measure; with a step, where\n"
    "      the pose is in that workspace: its cell, region per working mode, and per assembly\n"
    "      mode whether it is in the maximal workspace, reachable, and the distance to it;\n"
    "      last, the conditioning index of every working mode\n"
    "  workspace --robot FILE [--step S | --steps a,b,c] [--vars x,y,z] [--start x,y,z[,phi,theta,psi]]\n"
    "            [--start-mode NAME] [--bounds lo,hi,...] [--memory-budget BYTES] [--margin M]\n"
    "            [--min-region-voxels N] [--min-region-fraction F] [--threads N] [--uncoupled] [--modes a,b]\n"
    "            [--out DIR [--mesh stl|ply|obj [--mesh-triangles N] [--mesh-smoothing N]]]\n"
    "            [--conditioning [--conditioning-threshold T]] [--cache DIR | --no-cache] [--force] [--quiet]\n"
    "            [--tilt-max T --torsion lo,hi [--angle-step A]]\n"
    "      the maximal operational workspace: the workspace, singularity map, regions per\n"
    "      working mode, transitions, per assembly mode the maximal against the traditional\n"
    "      workspace; octrees, summary.json and transitions.csv into the cache and --out;\n"
    "      with --mesh, their boundary meshes into --out too; with --conditioning, per\n"
    "      assembly mode the volume where the conditioning index is at least T (default 0.1)\n"
    "      and the mean index (GCI); with --tilt-max, a 6-DOF platform's positions times\n"
    "      every orientation of tilt up to T (rad) and torsion in [lo, hi], and per position\n"
    "      the share of that set reached (total-orientation and inclusion workspaces)\n"
    "  plan --robot FILE (--goal x,y,z[,phi,theta,psi] | --random-goals N [--seed K])\n"
    "       [--from x,y,z[,phi,theta,psi]] [--from-mode NAME] [--goal-mode NAME] [--clearance C]\n"
    "       [--single-mode] [--time-limit S] [--max-velocity a,b,..] [--max-acceleration a,b,..]\n"
    "       [--transition-cost M] [--out PLAN.csv] [workspace options: --step, --cache, ...]\n"
    "      a path in the maximal operational workspace through IKP-singularity transitions, made\n"
    "      on the analysis at margin C (default 1e-3) within S seconds (default 5), its actuator\n"
    "      trajectory, and its check by DKP continuation; a refusal names its witness.\n"
    "      --random-goals: N goals that analysis calls reachable, each planned (the harness)\n"
    "  necks --robot FILE --margin M [--out NECKS.csv] [workspace options: --step, --cache, ...]\n"
    "      where the margin cuts exact regions into groups that were one: each neck's\n"
    "      |measure|, place, the measure along it and its cross-section\n"
    "  sweep --study STUDY.yaml [--out RESULTS.csv] [--jobs N] [--force] [--quiet]\n"
    "      a design study: the robot file with fields set to each design's values, one\n"
    "      analysis per design, one CSV row per design; run again to go on (docs/sweep.md).\n"
    "      Under mpirun -np N (mow built with MPI): rank 0 hands the designs to N-1 workers,\n"
    "      each analysing one at a time on --jobs threads (default 1)\n"
    "  verify --robot FILE --plan PLAN.csv [--uncoupled]\n"
    "      follow a plan's inputs through the DKP and check the platform follows the plan\n"
    "  urdf --robot FILE [--auxiliary] [--out FILE.urdf]\n"
    "      URDF of the robot (couples driven together) or of its uncoupled auxiliary\n"
    "\n"
    "  --uncoupled  use the 2^chains working modes of the uncoupled auxiliary mechanism\n"
    "               instead of the robot's 2^inputs\n"
    "  --memory-budget  bytes an analysis may take (suffix K, M, G: powers of 1024); default\n"
    "               half the machine's memory; a request estimated over it is refused at once\n"
    "\n"
    "Ctrl-C during an analysis stops it within about a second, caching nothing (a second\n"
    "Ctrl-C ends mow at once).\n"
    "\n"
    "exit codes: 0 success, 2 bad input (message on stderr), 3 no plan or a plan that fails\n"
    "verification, 130 interrupted, 1 internal error\n";

}  // namespace

int main(int argc, char** argv) {
  const std::vector<std::string> args(argv + 1, argv + argc);
  if (args.empty() || args[0] == "--help" || args[0] == "-h" || args[0] == "help") {
    (args.empty() ? std::cerr : std::cout) << kUsage;
    return args.empty() ? 2 : 0;
  }
  const std::vector<std::string> options(args.begin() + 1, args.end());
  try {
    if (args[0] == "info") return maximal_workspace::cli::runInfo(options);
    if (args[0] == "eval") return maximal_workspace::cli::runEval(options);
    if (args[0] == "workspace") return maximal_workspace::cli::runWorkspace(options);
    if (args[0] == "plan") return maximal_workspace::cli::runPlan(options);
    if (args[0] == "verify") return maximal_workspace::cli::runVerify(options);
    if (args[0] == "urdf") return maximal_workspace::cli::runUrdf(options);
    if (args[0] == "necks") return maximal_workspace::cli::runNecks(options);
    if (args[0] == "sweep") return maximal_workspace::cli::runSweep(options);
    std::cerr << "mow: unknown command '" << args[0] << "' (see mow --help)\n";
    return 2;
  } catch (const maximal_workspace::InputError& error) {
    std::cerr << "mow " << args[0] << ": " << error.what() << "\n";
    return 2;
  } catch (const maximal_workspace::Cancelled&) {
    std::cerr << "\nmow " << args[0] << ": interrupted; nothing was cached\n";
    return 130;
  } catch (const std::exception& error) {
    std::cerr << "mow " << args[0] << ": internal error: " << error.what() << "\n";
    return 1;
  }
}
