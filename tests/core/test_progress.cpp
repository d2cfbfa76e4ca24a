// Progress lines (meshgen/core/progress.hpp): nothing for a short stage, nothing when switched
// off, one refreshed line ending in a newline for a stage longer than the delay.
#include <gtest/gtest.h>

#include <chrono>
#include <string>
#include <thread>
#include <vector>

#include "meshgen/core/progress.hpp"

using namespace hm;

namespace {
std::string run_stage(bool enabled, double seconds, int64_t total) {
  set_progress_output(enabled, "prog");
  testing::internal::CaptureStderr();
  {
    Progress p("stage", total);
    std::vector<std::thread> workers;
    for (int t = 0; t < 4; ++t)
      workers.emplace_back([&] {
        for (int i = 0; i < total / 4; ++i) p.advance();
      });
    for (std::thread& w : workers) w.join();
    std::this_thread::sleep_for(std::chrono::duration<double>(seconds));
  }
  set_progress_output(false, "prog");
  return testing::internal::GetCapturedStderr();
}
}  // namespace

TEST(Progress, ShortStageOrSwitchedOffPrintsNothing) {
  EXPECT_EQ(run_stage(true, 0.3, 400), "");
  EXPECT_EQ(run_stage(false, kProgressDelaySeconds + 0.4, 400), "");
}

TEST(Progress, LongStageEndsWithItsFullLine) {
  const std::string out = run_stage(true, kProgressDelaySeconds + 0.4, 400);
  ASSERT_FALSE(out.empty());
  EXPECT_NE(out.find("\rprog: stage 100 % ("), std::string::npos) << out;
  EXPECT_EQ(out.back(), '\n');
  EXPECT_EQ(out.find('\n'), out.size() - 1);  // one line, refreshed in place
}

// Only the outermost live stage is shown.
TEST(Progress, NestedStageIsSilent) {
  set_progress_output(true, "prog");
  testing::internal::CaptureStderr();
  {
    Progress outer("outer");
    Progress inner("inner", 10);
    std::this_thread::sleep_for(std::chrono::duration<double>(kProgressDelaySeconds + 0.4));
  }
  set_progress_output(false, "prog");
  const std::string out = testing::internal::GetCapturedStderr();
  EXPECT_NE(out.find("outer"), std::string::npos) << out;
  EXPECT_EQ(out.find("inner"), std::string::npos) << out;
}
