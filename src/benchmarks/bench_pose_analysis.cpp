// Throughput of the per-pose analysis (IKP of every chain + the normalised det J_DKP of
// every working mode), the workspace engine's inner loop, against a plain reference
// written the obvious way. Run from the package root (robot files under config/), or
// give --config DIR. Own flags: --config DIR, --poses N (assembled poses per set).
//
// Pose sets: seeded-random TCP positions, uniform in the robot's safety box around the
// reference pose, at the reference orientation (one set also turned at random); only
// poses where every chain assembles are kept and counted. Elsewhere the classifier stops
// at the first chain that fails, so counting only assembled poses gives the conservative
// figure.
//
// The generic path (couples that do not factorise) is timed on the delta-like robot's 8
// working modes and its uncoupled auxiliary's 64, and on the 6-RSS hexapod's 64, in its
// batch form and against the per-mode LU it replaced (kept here only, to time against).
//
// BM_LimitsBatch/<robot>/<order>/{none,limits}: what checking a robot's limits costs, the
// robot file against the same file without its limits, on the same assembled positions,
// random or in grid-row order as the engine's batches come.

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <functional>
#include <map>
#include <memory>
#include <random>
#include <string>
#include <vector>

#include <benchmark/benchmark.h>
#include <Eigen/Geometry>
#include <Eigen/LU>
#include <yaml-cpp/yaml.h>

#include "maximal_workspace/kinematics/jacobian.h"
#include "maximal_workspace/kinematics/pose_classifier.h"
#include "maximal_workspace/kinematics/working_mode.h"
#include "maximal_workspace/model/robot_file.h"
#include "maximal_workspace/workspace/grid.h"
#include "workspace/parallel.h"

namespace maximal_workspace {
namespace {

[[noreturn]] void fail(const std::string& message) {
  std::fprintf(stderr, "bench_pose_analysis: %s\n", message.c_str());
  std::exit(1);
}

// The reference implementation: every chain's full IKP (inputs included) with
// Chain::solve, then per working mode a dynamic 6x6 twist-form J_DKP (rotational
// columns divided by the characteristic length) and its FullPivLU determinant over the
// product of its row norms (docs/kinematics.md). Shares no code with PoseClassifier
// beyond the chains' IKP. Spatial 6-DOF robots only.
bool plainAnalysis(const RobotModel& model, const std::vector<WorkingMode>& modes, const Pose& pose, double* measures) {
  const int chains = model.chainCount();
  std::array<Eigen::Vector3d, kMaxChains> p, r;
  std::array<ChainSolution, kMaxChains> solutions;
  for (int c = 0; c < chains; ++c) {
    p[c] = pose.toBase(model.chains[c]->platformNode());
    r[c] = p[c] - pose.position;
    solutions[c] = model.chains[c]->solve(p[c]);
    if (!solutions[c].assembled) return false;
  }
  Eigen::MatrixXd jacobian(chains, 6);
  for (std::size_t m = 0; m < modes.size(); ++m) {
    for (int c = 0; c < chains; ++c) {
      const Eigen::Vector3d g = p[c] - solutions[c].branch(modes[m].branch(c)).a;
      jacobian.row(c) << g.transpose(), r[c].cross(g).transpose() / model.characteristic_length;
    }
    const double norms = jacobian.rowwise().norm().prod();
    measures[m] = norms > 0.0 ? Eigen::FullPivLU<Eigen::MatrixXd>(jacobian).determinant() / norms : 0.0;
  }
  return true;
}

// Today's generic path before the shared-minor expansion, kept here to time against: per
// working mode, the twist-form J_DKP from jacobian.h and its partial-pivot LU
// (dkpSingularity), after each chain's IKP at the pose.
bool perModeLu(const RobotModel& model, const std::vector<WorkingMode>& modes, const Pose& pose, double* measures) {
  const Eigen::Matrix3d rotation = pose.rotation();
  const int chains = model.chainCount();
  std::array<std::array<DkpRow, 2>, kMaxChains> rows;
  for (int c = 0; c < chains; ++c) {
    const Eigen::Vector3d r = rotation * model.chains[c]->platformNode();
    const Eigen::Vector3d p = pose.position + r;
    const ChainNodes nodes = model.chains[c]->intermediateNodes(p);
    if (!nodes.assembled) return false;
    for (int b = 0; b < 2; ++b) rows[c][b] = dkpTwistRow(model, p - nodes.a[b], r);
  }
  DkpJacobian jacobian(chains, model.dof());
  for (std::size_t m = 0; m < modes.size(); ++m) {
    for (int c = 0; c < chains; ++c) jacobian.row(c) = rows[c][static_cast<int>(modes[m].branch(c))];
    measures[m] = dkpSingularity(model, jacobian).measure;
  }
  return true;
}

// Draws candidates until `count` of them are assembled (as `assembled` says). With
// `turn` > 0, each Euler angle is drawn too, within +/- turn (rad) of the reference.
std::vector<Pose> assembledPoses(const RobotModel& model, std::size_t count,
                                 const std::function<bool(const Pose&)>& assembled, double turn = 0.0) {
  std::vector<std::uniform_real_distribution<double>> coordinates;
  std::vector<OutputVariable> variables;
  for (OutputVariable variable : model.output_variables) {
    const bool rotational = isRotational(variable);
    if (rotational && turn <= 0.0) continue;
    const double reference = model.reference.pose.value(variable);
    const std::array<double, 2> box = rotational ? std::array<double, 2>{reference - turn, reference + turn}
                                                 : safetyBounds(model, model.reference.pose, variable);
    coordinates.emplace_back(box[0], box[1]);
    variables.push_back(variable);
  }
  std::mt19937_64 random(20240601);  // fixed: every run times the same poses
  std::vector<Pose> poses;
  for (std::size_t drawn = 0; poses.size() < count; ++drawn) {
    if (drawn > 1000 * count) fail(model.name + ": almost no pose of the safety box is assembled");
    Pose pose = model.reference.pose;
    for (std::size_t v = 0; v < variables.size(); ++v) pose.setValue(variables[v], coordinates[v](random));
    if (assembled(pose)) poses.push_back(pose);
  }
  return poses;
}

// What the check before timing found: a benchmark of wrong code is worthless.
struct Agreement {
  std::size_t candidates = 0, assembled = 0, signs_compared = 0;
  double max_difference = 0.0;  // largest |classifier - reference| over every measure
};

// True when the reference assembles the pose. Exits on any disagreement: assembly, or
// the sign of a working mode where the reference's |measure| > 1e-6.
bool checkAgainstReference(const RobotModel& model, const PoseClassifier& classifier, const Pose& pose,
                           Agreement& agreement) {
  const std::size_t modes = classifier.modes().size();
  std::vector<double> expected(modes), actual(modes);
  const bool assembled = plainAnalysis(model, classifier.modes(), pose, expected.data());
  const char* path = classifier.factorised() ? "factorised" : "generic";
  auto where = [&] {
    char text[256];
    std::snprintf(text, sizeof text, "pose (%.17g, %.17g, %.17g), ZYZ (%.17g, %.17g, %.17g)", pose.position.x(),
                  pose.position.y(), pose.position.z(), pose.euler_zyz.x(), pose.euler_zyz.y(), pose.euler_zyz.z());
    return std::string(text);
  };
  if (classifier.classify(pose, actual.data()) != assembled) {
    fail(std::string(path) + " classifier and reference disagree on assembly at " + where());
  }
  if (!assembled) return false;
  for (std::size_t m = 0; m < modes; ++m) {
    agreement.max_difference = std::max(agreement.max_difference, std::abs(actual[m] - expected[m]));
    if (std::abs(expected[m]) <= 1e-6) continue;
    ++agreement.signs_compared;
    if ((actual[m] > 0.0) != (expected[m] > 0.0)) {
      char values[120];
      std::snprintf(values, sizeof values, ": classifier %.17g, reference %.17g", actual[m], expected[m]);
      fail(std::string(path) + " classifier and reference disagree on the sign of working mode " +
           classifier.modes()[m].name + " at " + where() + values);
    }
  }
  return true;
}

// One pass over the pose set per iteration. A template, not std::function: no indirect
// call added to what is timed.
template <typename Analyse>
void timePasses(benchmark::State& state, const std::vector<Pose>& poses, std::size_t modes, const Analyse& analyse) {
  std::vector<double> measures(modes);
  for (auto _ : state) {
    for (const Pose& pose : poses) {
      benchmark::DoNotOptimize(analyse(pose, measures.data()));
      benchmark::ClobberMemory();  // the measures count as used
    }
  }
  state.SetItemsProcessed(static_cast<std::int64_t>(state.iterations() * poses.size()));
}

// Console output as usual; keeps each benchmark's items/s (the median when there are
// repetitions: aggregates come after the runs) for the speed-up ratios.
class RateReporter : public benchmark::ConsoleReporter {
 public:
  RateReporter() : ConsoleReporter(OO_None) {}  // plain text: the output goes into docs

  void ReportRuns(const std::vector<Run>& runs) override {
    ConsoleReporter::ReportRuns(runs);
    for (const Run& run : runs) {
      const auto rate = run.counters.find("items_per_second");
      if (run.error_occurred || rate == run.counters.end()) continue;
      if (run.run_type == Run::RT_Iteration || run.aggregate_name == "median") {
        rates_[run.run_name.function_name] = rate->second.value;
      }
    }
  }

  void printSpeedUp(const std::string& fast, const std::string& slow) const {
    const auto f = rates_.find(fast), s = rates_.find(slow);
    if (f == rates_.end() || s == rates_.end()) return;  // filtered out
    std::printf("speed-up %s over %s: %.1fx (%.3g vs %.3g poses/s)\n", fast.c_str(), slow.c_str(), f->second / s->second,
                f->second, s->second);
  }

 private:
  std::map<std::string, double> rates_;
};

struct Options {
  std::string config = "config";
  std::size_t poses = 100'000;
};

Options parseOptions(int argc, char** argv) {
  Options options;
  for (int i = 1; i < argc; ++i) {
    const std::string flag = argv[i];
    if (i + 1 == argc) fail("unknown or incomplete option '" + flag + "'");
    const std::string value = argv[++i];
    if (flag == "--config") {
      options.config = value;
    } else if (flag == "--poses") {
      options.poses = std::strtoull(value.c_str(), nullptr, 10);
      if (options.poses == 0) fail("--poses needs a positive count, got '" + value + "'");
    } else {
      fail("unknown option '" + flag + "'");
    }
  }
  return options;
}

// Poses per call of a batch form: the workspace engine's batch size.
constexpr std::size_t kEngineBatch = 1024;

// The generic path on one robot and working-mode list, over its own pose set, checked
// against the reference while it is drawn.
struct GenericCase {
  GenericCase(std::string case_name, const RobotModel& robot, std::vector<WorkingMode> mode_list, std::size_t count,
              double turn)
      : name(std::move(case_name)),
        model(robot),
        modes(std::move(mode_list)),
        classifier(model, modes, model.reference.pose, /*orientation_fixed=*/false) {
    if (classifier.factorised()) fail(name + ": the classifier does not take the generic path");
    poses = assembledPoses(
        model, count,
        [&](const Pose& pose) {
          ++agreement.candidates;
          const bool assembled = checkAgainstReference(model, classifier, pose, agreement);
          agreement.assembled += assembled;
          return assembled;
        },
        turn);
  }

  std::string name;
  const RobotModel& model;
  std::vector<WorkingMode> modes;
  PoseClassifier classifier;
  Agreement agreement;
  std::vector<Pose> poses;
};

void printAgreement(const std::string& what, const Agreement& agreement) {
  std::printf("%s: %zu assembled of %zu candidate poses; the classifier agrees with the reference on assembly and in "
              "%zu sign comparisons (|measure| > 1e-6); largest |measure difference| %.3g\n",
              what.c_str(), agreement.assembled, agreement.candidates, agreement.signs_compared,
              agreement.max_difference);
}

// BM_GenericPerModeLu/<case> (the path replaced) and BM_GenericBatch/<case> (the batch
// of poses, in the engine's batch size).
void registerGenericCase(const GenericCase& generic) {
  const std::size_t modes = generic.modes.size();
  benchmark::RegisterBenchmark(("BM_GenericPerModeLu/" + generic.name).c_str(), [&generic, modes](benchmark::State& state) {
    timePasses(state, generic.poses, modes, [&](const Pose& pose, double* m) {
      return perModeLu(generic.model, generic.modes, pose, m);
    });
  });
  benchmark::RegisterBenchmark(("BM_GenericBatch/" + generic.name).c_str(), [&generic, modes](benchmark::State& state) {
    std::vector<std::uint8_t> inside(kEngineBatch);
    std::vector<double> measures(kEngineBatch * modes);
    const std::size_t count = generic.poses.size();
    for (auto _ : state) {
      for (std::size_t begin = 0; begin < count; begin += kEngineBatch) {
        const std::size_t n = std::min(kEngineBatch, count - begin);
        generic.classifier.classify(&generic.poses[begin], n, inside.data(), measures.data());
        benchmark::DoNotOptimize(measures.data());
        benchmark::ClobberMemory();
      }
    }
    state.SetItemsProcessed(static_cast<std::int64_t>(state.iterations() * count));
  });
}

// The delta-like robot's factorised path in batches of TCP positions (vectorised
// kernels), on one thread and on all cores. `xs`, `ys`, `zs`: the pose set's positions.
void registerBatchBenchmarks(const PoseClassifier& factorised, const std::vector<double>& xs,
                             const std::vector<double>& ys, const std::vector<double>& zs) {
  const auto batch_pass = [&factorised, &xs, &ys, &zs](std::size_t begin, std::size_t end,
                                                        std::vector<std::uint8_t>& inside, std::vector<double>& measures) {
    const std::size_t count = end - begin;
    inside.resize(count);
    measures.resize(count * factorised.modes().size());
    factorised.classify(PointBatch{&xs[begin], &ys[begin], &zs[begin], count}, inside.data(), measures.data());
    benchmark::DoNotOptimize(measures.data());
    benchmark::ClobberMemory();
  };
  benchmark::RegisterBenchmark("BM_ClassifierBatch", [batch_pass, &xs](benchmark::State& state) {
    std::vector<std::uint8_t> inside;
    std::vector<double> measures;
    for (auto _ : state) batch_pass(0, xs.size(), inside, measures);
    state.SetItemsProcessed(static_cast<std::int64_t>(state.iterations() * xs.size()));
  });
  benchmark::RegisterBenchmark("BM_ClassifierBatchAllCores", [batch_pass, &xs](benchmark::State& state) {
    const int threads = resolveThreadCount(0);
    for (auto _ : state) {
      parallelFor(xs.size(), threads, [&](std::size_t begin, std::size_t end) {
        std::vector<std::uint8_t> inside;
        std::vector<double> measures;
        batch_pass(begin, end, inside, measures);
      });
    }
    state.SetItemsProcessed(static_cast<std::int64_t>(state.iterations() * xs.size()));
    state.counters["threads"] = threads;
  })->UseRealTime();
}

// The delta-like robot's factorised path pose by pose, on one thread and on all cores,
// and the plain reference on the same poses.
void registerFactorisedBenchmarks(const RobotModel& delta, const PoseClassifier& factorised,
                                  const std::vector<Pose>& poses) {
  const std::size_t modes = factorised.modes().size();
  benchmark::RegisterBenchmark("BM_ClassifierFactorised", [&, modes](benchmark::State& state) {
    timePasses(state, poses, modes, [&](const Pose& pose, double* m) { return factorised.classify(pose, m); });
  });
  benchmark::RegisterBenchmark("BM_PlainReference", [&, modes](benchmark::State& state) {
    timePasses(state, poses, modes,
               [&](const Pose& pose, double* m) { return plainAnalysis(delta, factorised.modes(), pose, m); });
  });
  benchmark::RegisterBenchmark("BM_ClassifierFactorisedAllCores", [&, modes](benchmark::State& state) {
    const int threads = resolveThreadCount(0);  // every hardware thread
    for (auto _ : state) {
      parallelFor(poses.size(), threads, [&](std::size_t begin, std::size_t end) {
        std::vector<double> measures(modes);
        for (std::size_t i = begin; i < end; ++i) {
          benchmark::DoNotOptimize(factorised.classify(poses[i], measures.data()));
          benchmark::ClobberMemory();
        }
      });
    }
    state.SetItemsProcessed(static_cast<std::int64_t>(state.iterations() * poses.size()));
    state.counters["threads"] = threads;
  })->UseRealTime();  // CPU time would be the main thread's alone
}

// The robot of a file without its limits (input ranges, cones, rod radii, clearance): the
// baseline of what checking them costs.
RobotModel withoutLimits(const std::string& path) {
  YAML::Node root = YAML::LoadFile(path);
  root.remove("clearance");
  for (YAML::Node input : root["inputs"]) input.remove("limits");
  for (YAML::Node chain : root["chains"]) {
    chain.remove("joint_limits");
    chain.remove("rod_radius");
  }
  return parseRobotFile(YAML::Dump(root), path + " without limits");
}

// A robot file with limits, the same robot without, and two sets of assembled positions
// at its reference orientation: random ones (the other benchmarks' set), and the
// assembled cells of a grid over the safety box in row order, as the engine's batches
// come (neighbouring cells, where a block's rods stay close together).
// BM_LimitsBatch/<name>/<order>/{none,limits} classify the same positions.
struct Positions {
  std::vector<double> xs, ys, zs;
  void add(const Eigen::Vector3d& p) {
    xs.push_back(p.x());
    ys.push_back(p.y());
    zs.push_back(p.z());
  }
};

struct LimitsCase {
  LimitsCase(const std::string& config, const std::string& file_name, std::size_t count)
      : name(file_name),
        limited(loadRobotFile(config + "/" + file_name + ".yaml")),
        unlimited(withoutLimits(config + "/" + file_name + ".yaml")),
        with(limited, coupledWorkingModes(limited), limited.reference.pose, true),
        without(unlimited, coupledWorkingModes(unlimited), unlimited.reference.pose, true) {
    std::vector<double> scratch(without.modes().size());
    const auto assembled = [&](const Pose& p) { return without.classify(p, scratch.data()); };
    for (const Pose& pose : assembledPoses(limited, count, assembled)) random.add(pose.position);
    std::array<std::array<double, 2>, 3> box;
    for (int k = 0; k < 3; ++k) box[k] = safetyBounds(limited, limited.reference.pose, static_cast<OutputVariable>(k));
    // A step giving about 3 count cells in the box, of which roughly a third assemble.
    const double volume = (box[0][1] - box[0][0]) * (box[1][1] - box[1][0]) * (box[2][1] - box[2][0]);
    const double step = std::cbrt(volume / (3.0 * count));
    Pose pose = limited.reference.pose;
    for (double x = box[0][0] + 0.5 * step; x < box[0][1] && rows.xs.size() < count; x += step) {
      for (double y = box[1][0] + 0.5 * step; y < box[1][1] && rows.xs.size() < count; y += step) {
        for (double z = box[2][0] + 0.5 * step; z < box[2][1] && rows.xs.size() < count; z += step) {
          pose.position = Eigen::Vector3d(x, y, z);
          if (assembled(pose)) rows.add(pose.position);
        }
      }
    }
  }
  std::string name;
  RobotModel limited, unlimited;
  PoseClassifier with, without;
  Positions random, rows;
};

void registerLimitsCase(const LimitsCase& limits) {
  for (const Positions* positions : {&limits.random, &limits.rows}) {
    for (const PoseClassifier* classifier : {&limits.without, &limits.with}) {
      const std::string name = "BM_LimitsBatch/" + limits.name + (positions == &limits.rows ? "/rows" : "/random") +
                               (classifier == &limits.with ? "/limits" : "/none");
      benchmark::RegisterBenchmark(name.c_str(), [positions, classifier](benchmark::State& state) {
        const std::size_t count = positions->xs.size();
        std::vector<std::uint8_t> inside(count);
        std::vector<double> measures(count * classifier->modes().size());
        for (auto _ : state) {
          // In the engine's batch size, as the engine calls it.
          for (std::size_t begin = 0; begin < count; begin += kEngineBatch) {
            const std::size_t n = std::min(kEngineBatch, count - begin);
            classifier->classify(PointBatch{&positions->xs[begin], &positions->ys[begin], &positions->zs[begin], n},
                                 &inside[begin], &measures[begin * classifier->modes().size()]);
          }
          benchmark::DoNotOptimize(measures.data());
          benchmark::ClobberMemory();
        }
        state.SetItemsProcessed(static_cast<std::int64_t>(state.iterations() * count));
      });
    }
  }
}

int run(int argc, char** argv) {
  benchmark::Initialize(&argc, argv);  // takes its own --benchmark_* flags out of argv
  const Options options = parseOptions(argc, argv);

  const RobotModel delta = loadRobotFile(options.config + "/delta_like.yaml");
  const RobotModel five_bar = loadRobotFile(options.config + "/five_bar.yaml");
  const RobotModel hexapod = loadRobotFile(options.config + "/hexapod_6rss.yaml");
  const PoseClassifier factorised(delta, coupledWorkingModes(delta), delta.reference.pose, /*orientation_fixed=*/true);
  const PoseClassifier five_bar_classifier(five_bar, coupledWorkingModes(five_bar), five_bar.reference.pose, true);
  if (!factorised.factorised()) fail("the delta-like classifier does not take the factorised path");

  Agreement agreement;
  const std::vector<Pose> delta_poses = assembledPoses(delta, options.poses, [&](const Pose& pose) {
    ++agreement.candidates;
    const bool assembled = checkAgainstReference(delta, factorised, pose, agreement);
    agreement.assembled += assembled;
    return assembled;
  });
  printAgreement("delta_like, factorised", agreement);
  std::vector<std::unique_ptr<GenericCase>> generic;
  generic.push_back(std::make_unique<GenericCase>("delta_8", delta, coupledWorkingModes(delta), options.poses, 0.0));
  generic.push_back(std::make_unique<GenericCase>("delta_64", delta, uncoupledWorkingModes(delta), options.poses, 0.0));
  generic.push_back(std::make_unique<GenericCase>("hexapod_64", hexapod, coupledWorkingModes(hexapod), options.poses, 0.0));
  // The same with every pose turned (up to 0.3 rad per Euler angle): a rotation per pose.
  generic.push_back(
      std::make_unique<GenericCase>("hexapod_64_turned", hexapod, coupledWorkingModes(hexapod), options.poses, 0.3));
  for (const auto& one : generic) printAgreement(one->model.name + ", generic, " + one->name, one->agreement);
  std::vector<double> scratch(five_bar_classifier.modes().size());
  const std::vector<Pose> five_bar_poses = assembledPoses(
      five_bar, options.poses, [&](const Pose& pose) { return five_bar_classifier.classify(pose, scratch.data()); });

  registerFactorisedBenchmarks(delta, factorised, delta_poses);
  const GenericCase& delta_8 = *generic.front();
  benchmark::RegisterBenchmark("BM_ClassifierGeneric", [&](benchmark::State& state) {
    timePasses(state, delta_8.poses, delta_8.modes.size(),
               [&](const Pose& pose, double* m) { return delta_8.classifier.classify(pose, m); });
  });
  for (const auto& one : generic) registerGenericCase(*one);
  std::vector<double> xs, ys, zs;
  for (const Pose& pose : delta_poses) {
    xs.push_back(pose.position.x());
    ys.push_back(pose.position.y());
    zs.push_back(pose.position.z());
  }
  registerBatchBenchmarks(factorised, xs, ys, zs);
  benchmark::RegisterBenchmark("BM_FiveBarClassifier", [&](benchmark::State& state) {
    timePasses(state, five_bar_poses, five_bar_classifier.modes().size(),
               [&](const Pose& pose, double* m) { return five_bar_classifier.classify(pose, m); });
  });

  std::vector<std::unique_ptr<LimitsCase>> limits;
  for (const char* file_name : {"delta_like_limited", "linear_delta", "rotary_delta"}) {
    limits.push_back(std::make_unique<LimitsCase>(options.config, file_name, options.poses));
    registerLimitsCase(*limits.back());
  }

  RateReporter reporter;
  benchmark::RunSpecifiedBenchmarks(&reporter);
  reporter.printSpeedUp("BM_ClassifierFactorised", "BM_PlainReference");
  reporter.printSpeedUp("BM_ClassifierGeneric", "BM_PlainReference");
  reporter.printSpeedUp("BM_ClassifierGeneric", "BM_GenericPerModeLu/delta_8");
  for (const auto& one : generic) reporter.printSpeedUp("BM_GenericBatch/" + one->name, "BM_GenericPerModeLu/" + one->name);
  reporter.printSpeedUp("BM_ClassifierBatch", "BM_ClassifierFactorised");
  for (const auto& one : limits) {
    for (const char* order : {"/random", "/rows"}) {
      const std::string prefix = "BM_LimitsBatch/" + one->name + order;
      reporter.printSpeedUp(prefix + "/limits", prefix + "/none");
    }
  }
  benchmark::Shutdown();
  return 0;
}

}  // namespace
}  // namespace maximal_workspace

int main(int argc, char** argv) {
  try {
    return maximal_workspace::run(argc, argv);
  } catch (const std::exception& error) {
    std::fprintf(stderr, "bench_pose_analysis: %s\n", error.what());
    return 1;
  }
}
