#pragma once
// Helpers shared by the test suites.
#include <functional>
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

}  // namespace vdyn::test
