// Parallel loops over index ranges on the TBB pool, without TBB in the headers. Bodies write
// per-index results; callers reduce them in index order, so every result is the same for any
// thread count (meshgen -j, fvcheck -j).
#pragma once
#include <cstdint>
#include <functional>
#include <memory>

namespace hm {

/// body(begin, end) over disjoint chunks covering [0, n), at most `grain` indices each.
void parallel_ranges(int64_t n, const std::function<void(int64_t, int64_t)>& body, int64_t grain = 2048);

/// Caps the threads of every TBB loop while alive; threads <= 0: every core.
class ThreadLimit {
 public:
  explicit ThreadLimit(int threads);
  ~ThreadLimit();
  ThreadLimit(const ThreadLimit&) = delete;
  ThreadLimit& operator=(const ThreadLimit&) = delete;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace hm
