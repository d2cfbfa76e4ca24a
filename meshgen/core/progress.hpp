// Progress of long stages on stderr: "meshgen: transition 40 % (3.1 s)", refreshed in place,
// shown only once a stage has run for kProgressDelaySeconds, and only when an executable has
// switched it on (set_progress_output: not with --quiet, not when stderr is no terminal).
// Library users and tests print nothing. Reporting never changes a result.
#pragma once
#include <atomic>
#include <cstdint>
#include <memory>
#include <string>

namespace hm {

/// A stage shorter than this prints nothing.
inline constexpr double kProgressDelaySeconds = 2.0;

/// Switches progress output on or off for the whole process; `program` prefixes the lines.
void set_progress_output(bool enabled, const std::string& program);
/// The executables' rule: on unless quiet, and only when stderr is a terminal.
bool progress_wanted(bool quiet);

/// One stage. total > 0: percent of `total` units (advance() from any thread); total == 0:
/// elapsed time only. Only the outermost live Progress is shown; nested ones count silently.
class Progress {
 public:
  Progress(std::string stage, int64_t total = 0);
  ~Progress();
  Progress(const Progress&) = delete;
  Progress& operator=(const Progress&) = delete;
  void advance(int64_t units = 1) { done_.fetch_add(units, std::memory_order_relaxed); }

  struct Display;  // the ticker thread (progress.cpp)

 private:
  std::atomic<int64_t> done_{0};
  std::unique_ptr<Display> display_;
};

}  // namespace hm
