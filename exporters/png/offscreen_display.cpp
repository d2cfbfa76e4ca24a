#include "exporters/png/offscreen_display.hpp"

#include <X11/Xlib.h>
#include <unistd.h>

#include <cerrno>
#include <climits>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <string>
#include <vector>

namespace hm {

std::string display_problem() {
  const char* name = std::getenv("DISPLAY");
  if (name == nullptr || *name == '\0') return "no X display (DISPLAY is not set)";
  Display* d = XOpenDisplay(name);
  if (d == nullptr) return std::string("cannot open the X display '") + name + "'";
  XCloseDisplay(d);
  return "";
}

DisplayConnection::DisplayConnection() {
  const char* name = std::getenv("DISPLAY");
  if (name == nullptr || *name == '\0') return;
  // A server that is resetting (its last client just left) refuses connections for a moment.
  for (int attempt = 0; attempt < 10 && display_ == nullptr; ++attempt) {
    if (attempt > 0) ::usleep(100000);
    display_ = XOpenDisplay(name);
  }
}

DisplayConnection::~DisplayConnection() {
  if (display_ != nullptr) XCloseDisplay(static_cast<Display*>(display_));
}

namespace {

/// The first executable `name` in $PATH, or "".
std::string find_on_path(const std::string& name) {
  const char* path = std::getenv("PATH");
  if (path == nullptr) return "";
  const std::string all = path;
  size_t start = 0;
  while (start <= all.size()) {
    const size_t colon = std::min(all.find(':', start), all.size());
    const std::string dir = all.substr(start, colon - start);
    if (!dir.empty()) {
      const std::string candidate = dir + "/" + name;
      if (::access(candidate.c_str(), X_OK) == 0) return candidate;
    }
    start = colon + 1;
  }
  return "";
}

}  // namespace

std::string ensure_display_or_rerun_under_xvfb(char** argv) {
  const std::string why = display_problem();
  if (why.empty()) return "";
  const bool rerun = std::getenv(kXvfbRerunVariable) != nullptr;
  const std::string xvfb_run = find_on_path("xvfb-run");
  if (rerun || xvfb_run.empty()) {
    return why + (rerun ? ", even under xvfb-run" : " and xvfb-run is not installed") +
           ": VTK's off-screen rendering needs an X server; install xvfb (scripts/install-deps.sh), "
           "run under `xvfb-run -a`, or leave out --png";
  }
  // This very executable (argv[0] may be a name found through PATH), with the same arguments.
  std::error_code ec;
  const std::string self = std::filesystem::read_symlink("/proc/self/exe", ec).string();
  if (ec || self.empty()) return why + " and the executable's own path is unknown (/proc/self/exe)";
  ::setenv(kXvfbRerunVariable, "1", 1);
  // -n before -a: xvfb-run looks for a free display number from N on; a start that depends on the
  // process id keeps concurrent runs (ctest -j) from racing for the same number.
  const std::string first_display = std::to_string(100 + ::getpid() % 800);
  std::vector<std::string> args = {xvfb_run, "-n", first_display, "-a", "-s", "-screen 0 1600x1200x24 -noreset", self};
  for (char** a = argv + 1; *a != nullptr; ++a) args.emplace_back(*a);
  std::vector<char*> cargs;
  for (std::string& s : args) cargs.push_back(s.data());
  cargs.push_back(nullptr);
  ::execv(xvfb_run.c_str(), cargs.data());
  return why + " and running xvfb-run failed: " + std::strerror(errno);
}

}  // namespace hm
