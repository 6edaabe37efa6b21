#include <algorithm>
#include <cstdio>
#include <iostream>
#include <map>
#include <sstream>

#include "analysis_request.h"
#include "commands.h"
#include "maximal_workspace/io/text_file.h"
#include "maximal_workspace/model/input_error.h"
#include "maximal_workspace/model/vector_text.h"
#include "maximal_workspace/regions/necks.h"

namespace maximal_workspace::cli {

namespace {

// The groups of the analysis with the margin, numbered per assembly mode from 1, the
// start's first, and how many non-debris regions each joins.
struct Groups {
  std::map<std::int32_t, int> number;
  std::map<std::int32_t, int> regions;
  std::map<std::int32_t, std::int8_t> sign;
};

Groups numberGroups(const WorkspaceAnalysis& analysis) {
  const std::vector<std::int32_t>& component = analysis.transitions().component;
  Groups groups;
  for (const Region& region : analysis.regions()) {
    if (region.debris) continue;
    ++groups.regions[component[region.id]];
    groups.sign[component[region.id]] = region.sign;
  }
  for (const AssemblyModeSummary& am : analysis.assemblyModes()) {
    int next = 1;
    if (am.traditional_region >= 0) groups.number[component[am.traditional_region]] = next++;
    for (const auto& [group, sign] : groups.sign) {
      if (sign == am.sign && !groups.number.count(group)) groups.number[group] = next++;
    }
  }
  return groups;
}

// The numbers of the two groups a neck joins, smaller first.
std::pair<int, int> joined(const Groups& groups, const Neck& neck) {
  const int a = groups.number.at(neck.groups[0]), b = groups.number.at(neck.groups[1]);
  return {std::min(a, b), std::max(a, b)};
}

void printGroups(const WorkspaceAnalysis& analysis, const Groups& groups) {
  for (const AssemblyModeSummary& am : analysis.assemblyModes()) {
    std::map<int, std::int32_t> in_order;
    for (const auto& [group, sign] : groups.sign) {
      if (sign == am.sign) in_order[groups.number.at(group)] = group;
    }
    std::cout << "assembly mode " << (am.sign > 0 ? '+' : '-') << ": " << am.components << " groups with the margin";
    for (const auto& [number, group] : in_order) {
      std::cout << (number == 1 ? ": " : ", ") << "group " << number << (number == 1 ? " (the start's): " : ": ")
                << groups.regions.at(group) << " regions";
    }
    std::cout << "\n";
  }
}

std::string necksCsv(const Grid& grid, const std::vector<WorkingMode>& modes, const Groups& groups,
                     const std::vector<Neck>& necks) {
  std::ostringstream csv;
  csv << "neck,assembly_mode,kind,group_a,group_b,neck_measure,sample,working_mode";
  for (int d = 0; d < grid.dims(); ++d) csv << "," << outputVariableName(grid.variable(d));
  csv << ",measure\n";
  for (std::size_t k = 0; k < necks.size(); ++k) {
    const Neck& neck = necks[k];
    for (std::size_t s = 0; s < neck.passage.size(); ++s) {
      csv << k + 1 << "," << (neck.sign > 0 ? "+" : "-") << ","
          << (neck.kind == Neck::Kind::Transition ? "transition" : "region") << "," << joined(groups, neck).first << ","
          << joined(groups, neck).second << "," << numberText(neck.measure) << "," << s << ","
          << modes[neck.passage[s].mode].name;
      for (int d = 0; d < grid.dims(); ++d) csv << "," << numberText(grid.coordinate(neck.passage[s].pose, d));
      csv << "," << numberText(neck.passage[s].measure) << "\n";
    }
  }
  return csv.str();
}

void printNeck(std::size_t number, const Neck& neck, const Grid& grid, const std::vector<WorkingMode>& modes,
               const Groups& groups) {
  const std::string where = neck.kind == Neck::Kind::Transition
                                ? "transition " + modes[neck.mode].name + " -> " + modes[neck.to_mode].name
                                : modes[neck.mode].name;
  std::printf("  neck %zu, %s, joins groups %d and %d: |measure| %.3g at %s\n", number, where.c_str(),
              joined(groups, neck).first, joined(groups, neck).second, neck.measure, gridPointText(grid, neck.pose).c_str());
  std::cout << "    passage under the margin: " << neck.passage.size() << " cells, |measure| along it:";
  for (std::size_t k = 0; k < neck.passage.size(); ++k) {
    const bool changes = k > 0 && neck.passage[k].mode != neck.passage[k - 1].mode;
    std::printf(changes ? " [%s] %.3g" : "%s %.3g", changes ? modes[neck.passage[k].mode].name.c_str() : "",
                neck.passage[k].measure);
  }
  std::cout << "\n";
  if (neck.cross_section_extent.empty()) return;
  if (neck.kind == Neck::Kind::Transition) {
    std::cout << "    width at half its measure: " << neck.cross_section_cells << " points of the transition, extent";
  } else {
    std::cout << "    width at half its measure: across " << outputVariableName(grid.variable(neck.cross_section_normal)) << ": "
              << neck.cross_section_cells << " cells" << (neck.cross_section_bounded ? "" : " (flood capped)") << ", extent";
  }
  for (int d = 0; d < grid.dims(); ++d) {
    if (d != neck.cross_section_normal) std::printf(" %s %.3g", outputVariableName(grid.variable(d)), neck.cross_section_extent[d]);
  }
  std::cout << "\n";
}

}  // namespace

int runNecks(const std::vector<std::string>& args) {
  const Arguments arguments(args, analysisValueOptions({"--out"}), analysisFlags());
  AnalysisRequest with_margin = analysisRequest(arguments);
  if (with_margin.options.margin <= 0.0) throw InputError("option --margin: required and over 0 (the necks are what a margin cuts)");
  AnalysisRequest exact = with_margin;
  exact.options.margin = 0.0;
  static_cast<ResolvedWorkspaceRequest&>(exact) =
      resolveAnalysis(exact.model, exact.robot_text, with_margin.spec, exact.options, with_margin.options.start_mode);

  ProgressBar bar;
  if (!arguments.flag("--quiet")) {
    exact.options.progress = with_margin.options.progress = [&bar](const AnalysisProgress& p) { bar.update(p); };
  }
  const std::shared_ptr<const WorkspaceAnalysis> exact_analysis = loadedWorkspace(arguments, exact, "necks");
  const std::shared_ptr<const WorkspaceAnalysis> margin_analysis = loadedWorkspace(arguments, with_margin, "necks");
  bar.finish();
  const std::vector<Neck> necks = findNecks(with_margin.model, *exact_analysis, *margin_analysis);

  const Grid& grid = margin_analysis->grid();
  std::cout << "necks that " << marginText(with_margin.options.margin) << " cuts (step "
            << numberText(grid.step(0)) << ", grid";
  for (int d = 0; d < grid.dims(); ++d) std::cout << " " << outputVariableName(grid.variable(d));
  std::cout << "): " << necks.size() << "\n";
  const Groups groups = numberGroups(*margin_analysis);
  printGroups(*margin_analysis, groups);
  for (std::size_t k = 0; k < necks.size(); ++k) {
    if (k == 0 || necks[k].sign != necks[k - 1].sign) std::cout << "assembly mode " << (necks[k].sign > 0 ? '+' : '-') << ":\n";
    printNeck(k + 1, necks[k], grid, margin_analysis->modes(), groups);
  }
  const std::string out = arguments.optional("--out", "");
  if (!out.empty()) {
    writeFileAtomically(out, necksCsv(grid, margin_analysis->modes(), groups, necks));
    std::cout << "written to " << out << "\n";
  }
  return 0;
}

}  // namespace maximal_workspace::cli
