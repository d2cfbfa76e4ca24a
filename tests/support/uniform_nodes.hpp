// Test helper shared by several suites: the nodes of a uniform axis.
#pragma once
#include <cmath>
#include <vector>

namespace hm::test {

/// Nodes lo, lo + h', ..., hi with h' = (hi - lo) / round((hi - lo) / h): the cell size closest to h
/// that divides [lo, hi] exactly, both ends included.
inline std::vector<double> uniform_nodes(double lo, double hi, double h) {
  std::vector<double> v;
  const int n = static_cast<int>(std::round((hi - lo) / h));
  for (int i = 0; i <= n; ++i) v.push_back(lo + (hi - lo) * i / n);
  return v;
}

}  // namespace hm::test
