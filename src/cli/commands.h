#pragma once
// The `mow` commands. Each returns the process exit code and throws InputError for bad
// input (reported by main with exit code 2).

#include <string>
#include <vector>

namespace maximal_workspace::cli {

int runInfo(const std::vector<std::string>& args);
int runEval(const std::vector<std::string>& args);
int runWorkspace(const std::vector<std::string>& args);
int runPlan(const std::vector<std::string>& args);
int runVerify(const std::vector<std::string>& args);
int runUrdf(const std::vector<std::string>& args);
int runNecks(const std::vector<std::string>& args);
int runSweep(const std::vector<std::string>& args);

}  // namespace maximal_workspace::cli
