#pragma once
// Internal: factories of the methods defined in separate files.
#include "vdyn/sensitivity/sensitivity.h"

namespace vdyn::detail {
std::unique_ptr<SensitivityMethod> makeMixedMethod(const SensitivitySettings& settings);
}  // namespace vdyn::detail
