#pragma once
// Cost functionals psi(b) over a named scene output y (the seed's (4.1b)):
//   integral_of_square  psi = int_0^T y(t)^2 dt         (the seed's (4.46))
//   maximum             psi = max_[0,T] y(t)
//   final_value         psi = y(T)
#include <string>
#include <vector>

namespace vdyn {

enum class CostKind { IntegralOfSquare, Maximum, FinalValue };

struct CostFunctional {
  CostKind kind = CostKind::IntegralOfSquare;
  /// Name of a scene output (e.g. "chassis.az_m_s2").
  std::string output;

  /// "integral_of_square", "maximum", "final_value".
  static const std::vector<std::string>& kindNames();
  /// Parses "<kind>:<output>", e.g. "integral_of_square:chassis.az_m_s2";
  /// throws Error naming the text if the kind is unknown or the output empty.
  static CostFunctional parse(const std::string& text);
  std::string kindName() const;
  std::string describe() const;  ///< "int_0^T y^2 dt of chassis.az_m_s2", ...
};

}  // namespace vdyn
