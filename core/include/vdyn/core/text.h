#pragma once
// Small text helpers shared by option and binding parsers.
#include <string>
#include <vector>

namespace vdyn {

/// Splits a comma-separated list ("a, b,c") into its items, each with
/// surrounding blanks removed; empty items are dropped.
inline std::vector<std::string> splitList(const std::string& list) {
  std::vector<std::string> out;
  std::string::size_type begin = 0;
  while (begin <= list.size()) {
    std::string::size_type end = list.find(',', begin);
    if (end == std::string::npos) end = list.size();
    const std::string::size_type first = list.find_first_not_of(" \t", begin);
    if (first != std::string::npos && first < end) {
      const std::string::size_type last = list.find_last_not_of(" \t", end - 1);
      out.push_back(list.substr(first, last - first + 1));
    }
    begin = end + 1;
  }
  return out;
}

}  // namespace vdyn
