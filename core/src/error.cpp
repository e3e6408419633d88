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

double requireFinite(double v, const std::string& name) {
  if (!std::isfinite(v))
    throw Error(name + " must be a finite number, got " + formatValue(v));
  return v;
}

double requirePositive(double v, const std::string& name) {
  requireFinite(v, name);
  if (!(v > 0)) throw Error(name + " must be positive, got " + formatValue(v));
  return v;
}

double requireNonNegative(double v, const std::string& name) {
  requireFinite(v, name);
  if (v < 0) throw Error(name + " must not be negative, got " + formatValue(v));
  return v;
}

double requireInRange(double v, double lo, double hi, const std::string& name) {
  requireFinite(v, name);
  if (v < lo || v > hi)
    throw Error(name + " must lie in [" + formatValue(lo) + ", " + formatValue(hi) +
                "], got " + formatValue(v));
  return v;
}

}  // namespace vdyn
