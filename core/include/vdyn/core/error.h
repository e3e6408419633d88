#pragma once
// Errors a user can cause (bad data, unknown plugin, non-physical value, solver
// failure) are reported by throwing vdyn::Error, whose message names the field or
// condition and the offending value. Internal invariants are asserts.
#include <cmath>
#include <sstream>
#include <stdexcept>
#include <string>

#include "vdyn/core/config.h"

namespace vdyn {

class Error : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// An error's message on one line (line breaks become spaces): what the
/// programs print after "error: " and what the Python module's vdyn.Error carries.
std::string oneLineMessage(const std::exception& e);

/// Formats a double the way error messages quote values (shortest round trip).
std::string formatValue(double v);

/// Throws Error("<name> must be a finite number, got <v>") unless v is finite.
double requireFinite(double v, const std::string& name);
/// Throws unless v is finite and > 0.
double requirePositive(double v, const std::string& name);
/// Throws unless v is finite and >= 0.
double requireNonNegative(double v, const std::string& name);
/// Throws unless v is finite and lo <= v <= hi.
double requireInRange(double v, double lo, double hi, const std::string& name);

}  // namespace vdyn
