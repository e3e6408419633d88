#pragma once
// Errors a user can cause (bad data, unknown plugin, non-physical value, solver
// failure) are reported by throwing vdyn::Error, whose message names the field or
// condition and the offending value. Internal invariants are asserts.
#include <cmath>
#include <sstream>
#include <stdexcept>
#include <string>
#include <string_view>

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

namespace detail {
// The messages of the checks below, built only when a check fails.
[[noreturn]] void throwNotFinite(double v, std::string_view name);
[[noreturn]] void throwNotPositive(double v, std::string_view name);
[[noreturn]] void throwNegative(double v, std::string_view name);
[[noreturn]] void throwOutOfRange(double v, double lo, double hi, std::string_view name);
}  // namespace detail

// The checks are inline and take the name as a view: they sit in evaluation
// paths (a tire's or a law's inputs at every evaluation), where building a
// std::string from the name's literal cost an allocation per call.

/// Throws Error("<name> must be a finite number, got <v>") unless v is finite.
inline double requireFinite(double v, std::string_view name) {
  if (!std::isfinite(v)) detail::throwNotFinite(v, name);
  return v;
}
/// Throws unless v is finite and > 0.
inline double requirePositive(double v, std::string_view name) {
  if (!(v > 0 && std::isfinite(v))) detail::throwNotPositive(v, name);
  return v;
}
/// Throws unless v is finite and >= 0.
inline double requireNonNegative(double v, std::string_view name) {
  if (!(v >= 0 && std::isfinite(v))) detail::throwNegative(v, name);
  return v;
}
/// Throws unless v is finite and lo <= v <= hi.
inline double requireInRange(double v, double lo, double hi, std::string_view name) {
  if (!(v >= lo && v <= hi && std::isfinite(v))) detail::throwOutOfRange(v, lo, hi, name);
  return v;
}

}  // namespace vdyn
