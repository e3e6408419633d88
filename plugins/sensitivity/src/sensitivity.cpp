#include "vdyn/sensitivity/sensitivity.h"

#include <algorithm>
#include <chrono>
#include <cmath>

#include "methods.h"
#include "vdyn/core/simulation.h"

namespace vdyn {

void SensitivityProblem::validate() const {
  if (!model) throw Error("sensitivity problem: no design model");
  if (parameters.empty()) throw Error("sensitivity problem: no design parameters");
  const auto idx = parameterIndices();
  for (std::size_t i = 0; i < idx.size(); ++i)
    for (std::size_t j = 0; j < i; ++j)
      if (idx[i] == idx[j])
        throw Error("sensitivity problem: design parameter '" + model->getParameters()[idx[i]].name +
                    "' is listed twice");
  if (cost.output.empty()) throw Error("sensitivity problem: the cost names no output");
  requirePositive(t_end_s, "sensitivity problem t_end_s");
  integrator.validate();
}

std::vector<int> SensitivityProblem::parameterIndices() const {
  std::vector<int> idx;
  for (const auto& n : parameters) idx.push_back(model->findParameter(n));
  return idx;
}

double relativePerturbation(double eps, bool central) {
  eps = std::max(eps, 1e-15);
  return central ? std::cbrt(eps) : std::sqrt(eps);
}

double evaluateCost(const SensitivityProblem& problem, const std::vector<double>& b,
                    const IntegratorSettings& integrator) {
  auto inst = problem.model->build(b);
  Scene& sc = inst->updScene();
  const CostFunctional& c = problem.cost;
  sc.getOutput(c.output);  // names the known outputs if it is missing
  IntegralHandle h;
  if (c.kind == CostKind::IntegralOfSquare) h = sc.addIntegralOfSquare(c.output);
  SimTK::State s = inst->makeInitialState();
  SimulationSettings sim;
  sim.t_end_s = s.getTime() + problem.t_end_s;
  sim.report_interval_s = 0;
  sim.integrator = integrator;
  double maxValue = -SimTK::Infinity;
  std::function<void(const SimTK::State&)> afterStep;
  if (c.kind == CostKind::Maximum) {
    maxValue = sc.evalOutput(c.output, s);
    afterStep = [&](const SimTK::State& adv) { maxValue = std::max(maxValue, sc.evalOutput(c.output, adv)); };
  }
  simulate(sc, s, sim, nullptr, afterStep);
  double psi = 0;
  switch (c.kind) {
    case CostKind::IntegralOfSquare: psi = sc.getIntegral(h, s); break;
    case CostKind::Maximum: psi = maxValue; break;
    case CostKind::FinalValue: psi = sc.evalOutput(c.output, s); break;
  }
  return requireFinite(psi, "cost " + c.describe());
}

// ---------------------------------------------------------------------------
SensitivityMethod::SensitivityMethod(std::string name, SensitivitySettings settings)
    : name_(std::move(name)), settings_(settings) {
  requireNonNegative(settings_.perturbation, name_ + " perturbation");
  if (!(settings_.perturbation < 1)) throw Error(name_ + " perturbation must be below 1 (relative), got " +
                                                 formatValue(settings_.perturbation));
  requirePositive(settings_.tolerance, name_ + " tolerance");
  if (settings_.initial_intervals < 3)
    throw Error(name_ + " initial_intervals must be at least 3, got " + std::to_string(settings_.initial_intervals));
  if (settings_.max_levels < 2 || settings_.max_levels > 16)
    throw Error(name_ + " max_levels must lie in [2, 16], got " + std::to_string(settings_.max_levels));
  requireInRange(settings_.reference_accuracy, 1e-15, 1e-6, name_ + " reference_accuracy");
  requireInRange(settings_.reference_perturbation, 1e-8, 0.1, name_ + " reference_perturbation");
}

SensitivityResult SensitivityMethod::compute(const SensitivityProblem& problem) const {
  problem.validate();
  const auto wall0 = std::chrono::steady_clock::now();
  SensitivityResult r = DoCompute(problem);
  r.wall_time_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - wall0).count();
  r.method = name_;
  r.parameters.clear();
  for (int i : problem.parameterIndices()) r.parameters.push_back(problem.model->getParameters()[i].name);
  assert(r.dpsi_db.size() == r.parameters.size());
  for (std::size_t i = 0; i < r.dpsi_db.size(); ++i)
    requireFinite(r.dpsi_db[i], name_ + " d psi / d " + r.parameters[i]);
  return r;
}

namespace {

/// Central or forward differences of psi with relative steps rel (per call).
struct Differences {
  std::vector<double> d, delta;
  int sims = 0;
};

Differences differences(const SensitivityProblem& p, const IntegratorSettings& integ, double rel, bool central,
                        double psi0) {
  const auto idx = p.parameterIndices();
  const auto& params = p.model->getParameters();
  const std::vector<double> b0 = p.model->getNominalValues();
  Differences out;
  for (int i : idx) {
    const double h = rel * std::max(std::abs(b0[i]), params[i].scale);
    std::vector<double> bp = b0;
    bp[i] += h;
    const double psiPlus = evaluateCost(p, bp, integ);
    ++out.sims;
    if (central) {
      std::vector<double> bm = b0;
      bm[i] -= h;
      const double psiMinus = evaluateCost(p, bm, integ);
      ++out.sims;
      out.d.push_back((psiPlus - psiMinus) / (2 * h));  // (4.22)
    } else {
      out.d.push_back((psiPlus - psi0) / h);  // (4.21)
    }
    out.delta.push_back(h);
  }
  return out;
}

class FiniteDifferenceMethod : public SensitivityMethod {
 public:
  FiniteDifferenceMethod(bool central, SensitivitySettings s)
      : SensitivityMethod(central ? "fd_central" : "fd_forward", s), central_(central) {}

 protected:
  SensitivityResult DoCompute(const SensitivityProblem& p) const override {
    SensitivityResult r;
    r.psi = evaluateCost(p, p.model->getNominalValues(), p.integrator);
    const double rel = settings().perturbation > 0 ? settings().perturbation
                                                   : relativePerturbation(p.integrator.accuracy, central_);
    Differences d = differences(p, p.integrator, rel, central_, r.psi);
    r.dpsi_db = d.d;
    r.perturbation = d.delta;
    r.simulations = 1 + d.sims;
    return r;
  }

 private:
  bool central_;
};

class ReferenceMethod : public SensitivityMethod {
 public:
  explicit ReferenceMethod(SensitivitySettings s) : SensitivityMethod("reference", s) {}

 protected:
  SensitivityResult DoCompute(const SensitivityProblem& p) const override {
    IntegratorSettings integ = p.integrator;
    integ.accuracy = settings().reference_accuracy;
    SensitivityResult r;
    r.psi = evaluateCost(p, p.model->getNominalValues(), integ);
    const double rel = settings().reference_perturbation;
    const Differences d1 = differences(p, integ, rel, true, r.psi);
    const Differences d2 = differences(p, integ, rel / 2, true, r.psi);
    for (std::size_t i = 0; i < d1.d.size(); ++i) {
      // Central differences have an h^2, h^4, ... error expansion: Richardson
      // removes the h^2 term; the two sizes must agree (their difference is
      // 3/4 of the h^2 error of the larger one).
      const double disagreement = std::abs(d1.d[i] - d2.d[i]);
      const double agreement = settings().reference_agreement;
      if (!(disagreement <= agreement * std::abs(d2.d[i]) + 1e-300))
        throw Error("reference: the central differences with relative perturbations " + formatValue(rel) + " and " +
                    formatValue(rel / 2) + " disagree for " + p.parameters[i] + ": " + formatValue(d1.d[i]) +
                    " vs " + formatValue(d2.d[i]) + " (more than " + formatValue(agreement) + " relative)");
      r.dpsi_db.push_back((4 * d2.d[i] - d1.d[i]) / 3);
      r.error_estimate.push_back(disagreement);
      r.perturbation.push_back(d1.delta[i]);
    }
    r.simulations = 1 + d1.sims + d2.sims;
    return r;
  }
};

}  // namespace

MixedRefinement mixedRefinementFromName(const std::string& name, const std::string& where) {
  if (name == "uniform") return MixedRefinement::Uniform;
  if (name == "adaptive") return MixedRefinement::Adaptive;
  throw Error(where + ": expected uniform or adaptive, got '" + name + "'");
}

const std::vector<std::string>& sensitivityMethodNames() {
  static const std::vector<std::string> names = {"fd_forward", "fd_central", "mixed", "reference"};
  return names;
}

void registerSensitivityMethods(PluginRegistry& registry) {
  using S = SensitivitySettings;
  registry.addChoice<SensitivityMethod, S>(
      "sensitivity_method", "fd_forward",
      [](const ParamReader&, const S& s) { return std::make_unique<FiniteDifferenceMethod>(false, s); },
      typeInfo("forward differences (4.21): r + 1 simulations, step sqrt(eps) max(|b|, scale); no keys of its own "
               "(the sensitivity analysis's perturbation)",
               noFields()));
  registry.addChoice<SensitivityMethod, S>(
      "sensitivity_method", "fd_central",
      [](const ParamReader&, const S& s) { return std::make_unique<FiniteDifferenceMethod>(true, s); },
      typeInfo("central differences (4.22): 2 r + 1 simulations, step cbrt(eps) max(|b|, scale); no keys of its own "
               "(the sensitivity analysis's perturbation)",
               noFields()));
  registry.addChoice<SensitivityMethod, S>(
      "sensitivity_method", "mixed", [](const ParamReader&, const S& s) { return detail::makeMixedMethod(s); },
      typeInfo("the mixed method (4.23)-(4.44): sensitivity equations with finite-difference coefficients at steps of "
               "one simulation, integrated by Radau IIA; no keys of its own (the sensitivity analysis's tolerance and "
               "refinement)",
               noFields()));
  registry.addChoice<SensitivityMethod, S>(
      "sensitivity_method", "reference",
      [](const ParamReader&, const S& s) { return std::make_unique<ReferenceMethod>(s); },
      typeInfo("central differences at a tight accuracy with two perturbation sizes that must agree (Richardson)",
               noFields()));
}

namespace {
const PluginRegistry& builtinMethods() {
  static const PluginRegistry r = [] {
    PluginRegistry reg;
    registerSensitivityMethods(reg);
    return reg;
  }();
  return r;
}
}  // namespace

std::unique_ptr<SensitivityMethod> makeSensitivityMethod(const std::string& name, const SensitivitySettings& s,
                                                         const PluginRegistry* registry) {
  const PluginRegistry& reg = registry ? *registry : builtinMethods();
  const ParamReader none = ParamReader::fromJson(Json::object(), "sensitivity method '" + name + "'");
  return reg.createChoice<SensitivityMethod, SensitivitySettings>("sensitivity_method", name, none, s, "");
}

}  // namespace vdyn
