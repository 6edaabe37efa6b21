#pragma once
// Running the mow binary from a test, and temporary directories. MOW_BINARY is the path
// of the built binary (a compile definition; without it, runMow is left out).

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <functional>
#include <stdexcept>
#include <string>
#include <vector>

#include <fcntl.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

extern char** environ;

namespace maximal_workspace {
namespace test {

// A fresh directory under /tmp, removed with everything in it.
class TempDir {
 public:
  TempDir() {
    char pattern[] = "/tmp/mow_cli_test_XXXXXX";
    if (::mkdtemp(pattern) == nullptr) throw std::runtime_error("mkdtemp failed");
    path_ = pattern;
  }
  ~TempDir() {
    std::error_code ignored;
    std::filesystem::remove_all(path_, ignored);
  }
  TempDir(const TempDir&) = delete;
  TempDir& operator=(const TempDir&) = delete;

  std::string file(const std::string& name) const { return path_ + "/" + name; }

 private:
  std::string path_;
};

inline std::string readFile(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream text;
  text << in.rdbuf();
  return text.str();
}

inline void writeFile(const std::string& path, const std::string& content) {
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  out << content;
  if (!out) throw std::runtime_error("cannot write " + path);
}

struct RunResult {
  int exit_code = -1;
  std::string out;
  std::string err;
};

// What a finished mow run gave: its exit status and its captured output, whose files are
// then removed.
inline RunResult collectRun(int status, const std::string& out_path, const std::string& err_path) {
  RunResult result;
  result.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
  result.out = readFile(out_path);
  result.err = readFile(err_path);
  std::remove(out_path.c_str());
  std::remove(err_path.c_str());
  return result;
}

#ifdef MOW_BINARY
// Runs MOW_BINARY with `args` (no shell: each argument reaches mow as it is). stdout and
// stderr go to two capture files in `capture`, read back and removed. `during`, when
// given, is called once mow runs, with its pid and the path of its stderr capture.
// `launcher`, when given, starts mow: a program's absolute path and its arguments before
// mow's (mpirun -np 3); `during` then gets the launcher's pid.
inline RunResult runMow(const std::vector<std::string>& args, const TempDir& capture,
                        const std::function<void(pid_t, const std::string&)>& during = {},
                        const std::vector<std::string>& launcher = {}) {
  const std::string out_path = capture.file("captured.stdout");
  const std::string err_path = capture.file("captured.stderr");
  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  posix_spawn_file_actions_addopen(&actions, STDIN_FILENO, "/dev/null", O_RDONLY, 0);
  posix_spawn_file_actions_addopen(&actions, STDOUT_FILENO, out_path.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0600);
  posix_spawn_file_actions_addopen(&actions, STDERR_FILENO, err_path.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0600);

  std::vector<std::string> strings = launcher;
  strings.push_back(MOW_BINARY);
  strings.insert(strings.end(), args.begin(), args.end());
  std::vector<char*> argv;
  for (std::string& s : strings) argv.push_back(s.data());
  argv.push_back(nullptr);

  pid_t pid = 0;
  const int spawned = posix_spawn(&pid, strings[0].c_str(), &actions, nullptr, argv.data(), environ);
  posix_spawn_file_actions_destroy(&actions);
  if (spawned != 0) throw std::runtime_error("cannot run " + strings[0] + ": " + std::strerror(spawned));
  if (during) during(pid, err_path);
  int status = 0;
  while (::waitpid(pid, &status, 0) < 0) {
    if (errno != EINTR) throw std::runtime_error("waitpid failed");
  }
  return collectRun(status, out_path, err_path);
}
#endif  // MOW_BINARY

}  // namespace test
}  // namespace maximal_workspace
