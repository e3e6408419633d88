#include "vdyn/sensitivity/design.h"

#include <cmath>

#include "vdyn/sensitivity/cost.h"

namespace vdyn {

DesignModel::DesignModel(std::vector<DesignParameter> params) : params_(std::move(params)) {
  for (const auto& p : params_) {
    assert(!p.name.empty());
    assert(p.scale > 0);
  }
}

std::vector<double> DesignModel::getNominalValues() const {
  std::vector<double> b;
  for (const auto& p : params_) b.push_back(p.nominal);
  return b;
}

int DesignModel::findParameter(const std::string& name) const {
  for (std::size_t i = 0; i < params_.size(); ++i)
    if (params_[i].name == name || params_[i].symbol == name) return static_cast<int>(i);
  std::string list;
  for (const auto& p : params_) list += (list.empty() ? "" : ", ") + p.name;
  throw Error(describe() + " has no design parameter '" + name + "'; known: " + list);
}

std::unique_ptr<DesignInstance> DesignModel::build(const std::vector<double>& values) const {
  if (values.size() != params_.size())
    throw Error(describe() + ": design vector has " + std::to_string(values.size()) + " values, the model has " +
                std::to_string(params_.size()) + " parameters");
  for (std::size_t i = 0; i < values.size(); ++i) requireFinite(values[i], describe() + " design parameter " + params_[i].name);
  auto inst = DoBuild(values);
  assert(inst);
  return inst;
}

// ---------------------------------------------------------------------------
const std::vector<std::string>& CostFunctional::kindNames() {
  static const std::vector<std::string> names = {"integral_of_square", "maximum", "final_value"};
  return names;
}

CostFunctional CostFunctional::parse(const std::string& text) {
  const auto colon = text.find(':');
  if (colon == std::string::npos || colon + 1 == text.size())
    throw Error("cost '" + text + "' must read <kind>:<output>, e.g. integral_of_square:chassis.az_m_s2");
  const std::string kind = text.substr(0, colon);
  CostFunctional c;
  c.output = text.substr(colon + 1);
  if (kind == "integral_of_square") c.kind = CostKind::IntegralOfSquare;
  else if (kind == "maximum") c.kind = CostKind::Maximum;
  else if (kind == "final_value") c.kind = CostKind::FinalValue;
  else
    throw Error("unknown cost kind '" + kind + "'; known: integral_of_square, maximum, final_value");
  return c;
}

std::string CostFunctional::kindName() const { return kindNames()[static_cast<int>(kind)]; }

std::string CostFunctional::describe() const {
  switch (kind) {
    case CostKind::IntegralOfSquare: return "int_0^T y^2 dt of " + output;
    case CostKind::Maximum: return "max_t y of " + output;
    case CostKind::FinalValue: return "y(T) of " + output;
  }
  return "?";
}

}  // namespace vdyn
