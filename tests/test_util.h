#pragma once
// Helpers shared by the test suites.
#include <fstream>
#include <functional>
#include <sstream>
#include <string>

#include "vdyn/core/error.h"

namespace vdyn::test {

/// The message of the vdyn::Error that `f` throws, or "(no error)".
inline std::string errorOf(const std::function<void()>& f) {
  try {
    f();
  } catch (const Error& e) {
    return e.what();
  }
  return "(no error)";
}

/// The whole text of the file at `path` ("" if it cannot be read).
inline std::string readTextFile(const std::string& path) {
  std::ifstream in(path);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

}  // namespace vdyn::test
