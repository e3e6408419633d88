#pragma once
// Small helpers shared by the benchmarks.
#include "vdyn/core/text.h"
#include <algorithm>
#include <sstream>
#include <string>
#include <vector>

namespace vdyn::bench {
using vdyn::splitList;

inline double median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  const std::size_t n = v.size();
  return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

inline std::vector<double> splitNumbers(const std::string& s) {
  std::vector<double> v;
  for (const auto& item : splitList(s)) v.push_back(std::stod(item));
  return v;
}

}  // namespace vdyn::bench
