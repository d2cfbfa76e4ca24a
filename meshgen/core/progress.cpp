#include "progress.hpp"

#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <condition_variable>
#include <cstdio>
#include <mutex>
#include <thread>

namespace hm {

namespace {

std::atomic<bool> g_enabled{false};
std::atomic<int> g_live{0};  // live Progress objects (only the outermost is shown)
std::string g_program = "hm";
std::mutex g_program_mutex;

}  // namespace

void set_progress_output(bool enabled, const std::string& program) {
  {
    std::lock_guard<std::mutex> lock(g_program_mutex);
    g_program = program;
  }
  g_enabled = enabled;
}

bool progress_wanted(bool quiet) { return !quiet && isatty(STDERR_FILENO) == 1; }

// A thread that wakes every 0.25 s and, past the delay, rewrites the stage's line.
struct Progress::Display {
  std::string stage, program;
  int64_t total = 0;
  const std::atomic<int64_t>* done = nullptr;
  std::chrono::steady_clock::time_point start = std::chrono::steady_clock::now();
  std::mutex m;
  std::condition_variable cv;
  bool stop = false, shown = false;
  std::thread ticker;

  double elapsed() const {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  }
  void print(bool final) {
    char pct[32] = "";
    if (total > 0) {
      const int64_t d = final ? total : std::min<int64_t>(done->load(std::memory_order_relaxed), total);
      std::snprintf(pct, sizeof pct, " %3d %%", static_cast<int>(100 * d / total));
    }
    std::fprintf(stderr, "\r%s: %s%s (%.1f s)%s", program.c_str(), stage.c_str(), pct, elapsed(), final ? "\n" : "");
    std::fflush(stderr);
    shown = true;
  }
  void run() {
    std::unique_lock<std::mutex> lock(m);
    while (!cv.wait_for(lock, std::chrono::milliseconds(250), [&] { return stop; }))
      if (elapsed() >= kProgressDelaySeconds) print(false);
    if (shown) print(true);
  }
};

Progress::Progress(std::string stage, int64_t total) {
  const bool outermost = g_live.fetch_add(1) == 0;
  if (!outermost || !g_enabled) return;
  display_ = std::make_unique<Display>();
  display_->stage = std::move(stage);
  {
    std::lock_guard<std::mutex> lock(g_program_mutex);
    display_->program = g_program;
  }
  display_->total = total;
  display_->done = &done_;
  display_->ticker = std::thread([d = display_.get()] { d->run(); });
}

Progress::~Progress() {
  if (display_) {
    {
      std::lock_guard<std::mutex> lock(display_->m);
      display_->stop = true;
    }
    display_->cv.notify_one();
    display_->ticker.join();
  }
  g_live.fetch_sub(1);
}

}  // namespace hm
