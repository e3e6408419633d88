#include "vdyn/core/error.h"

#include <cstdio>

namespace vdyn {

std::string oneLineMessage(const std::exception& e) {
  std::string msg = e.what();
  for (auto& c : msg)
    if (c == '\n') c = ' ';
  return msg;
}

std::string formatValue(double v) {
  // Plain notation where 15 significant digits round-trip (-200, 0.02, 1e-05);
  // 17 digits otherwise.
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.15g", v);
  if (std::isnan(v) || std::strtod(buf, nullptr) == v) return buf;
  std::snprintf(buf, sizeof buf, "%.17g", v);
  return buf;
}

namespace detail {

void throwNotFinite(double v, std::string_view name) {
  throw Error(std::string(name) + " must be a finite number, got " + formatValue(v));
}

void throwNotPositive(double v, std::string_view name) {
  if (!std::isfinite(v)) throwNotFinite(v, name);
  throw Error(std::string(name) + " must be positive, got " + formatValue(v));
}

void throwNegative(double v, std::string_view name) {
  if (!std::isfinite(v)) throwNotFinite(v, name);
  throw Error(std::string(name) + " must not be negative, got " + formatValue(v));
}

void throwOutOfRange(double v, double lo, double hi, std::string_view name) {
  if (!std::isfinite(v)) throwNotFinite(v, name);
  throw Error(std::string(name) + " must lie in [" + formatValue(lo) + ", " + formatValue(hi) + "], got " +
              formatValue(v));
}

}  // namespace detail

}  // namespace vdyn
