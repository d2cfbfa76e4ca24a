// Runs a shell command for end-to-end tests, capturing exit code, stdout and stderr.
#pragma once
#include <sys/wait.h>
#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

namespace hm_test {

struct CommandResult {
  int exit_code = -1;
  std::string out, err;
};

inline std::string slurp(const std::filesystem::path& p) {
  std::ifstream f(p, std::ios::binary);
  std::ostringstream ss;
  ss << f.rdbuf();
  return ss.str();
}

/// Runs `command` through /bin/sh with a time limit (seconds); stdout/stderr go to temp files.
inline CommandResult run_command(const std::string& command, int timeout_s = 600) {
  namespace fs = std::filesystem;
  static int counter = 0;
  const fs::path dir = fs::temp_directory_path() / ("hm_cmd_" + std::to_string(::getpid()) + "_" + std::to_string(counter++));
  fs::create_directories(dir);
  const std::string full = "timeout " + std::to_string(timeout_s) + " " + command + " > '" + (dir / "out").string() +
                           "' 2> '" + (dir / "err").string() + "'";
  const int status = std::system(full.c_str());
  CommandResult r;
  r.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  r.out = slurp(dir / "out");
  r.err = slurp(dir / "err");
  fs::remove_all(dir);
  return r;
}

/// A path quoted for the shell.
inline std::string q(const std::filesystem::path& p) { return "'" + p.string() + "'"; }

/// Removes a test's directory at scope exit (flow and checkMesh outputs are large), unless
/// HM_KEEP_TEST_OUTPUT is set.
struct RemoveAtExit {
  std::filesystem::path dir;
  ~RemoveAtExit() {
    std::error_code ec;
    if (std::getenv("HM_KEEP_TEST_OUTPUT") == nullptr) std::filesystem::remove_all(dir, ec);
  }
};

/// A fresh temporary directory for one test.
inline std::filesystem::path fresh_dir(const std::string& name) {
  namespace fs = std::filesystem;
  const fs::path d = fs::temp_directory_path() / ("hm_e2e_" + std::to_string(::getpid()) + "_" + name);
  fs::remove_all(d);
  fs::create_directories(d);
  return d;
}

}  // namespace hm_test
