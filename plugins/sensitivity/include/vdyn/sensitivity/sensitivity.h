#pragma once
// Design sensitivity d psi / d b (the seed's chapter 4) by methods chosen by name:
//
//   fd_forward  forward differences (4.21): r + 1 simulations
//   fd_central  central differences (4.22): 2 r + 1 simulations
//   mixed       the mixed method (4.23)-(4.44): direct-differentiation
//               sensitivity equations whose coefficient matrices are finite
//               differences of the equations-of-motion residual (Simbody
//               inverse dynamics), sampled at steps of the nominal run,
//               interpolated by cubics and integrated apart from it by
//               two-stage Radau IIA; nodes refined pass by pass until the
//               change of d psi / d b is below the tolerance (see mixed.h)
//   reference   central differences at a tight integrator tolerance with two
//               perturbation sizes that must agree; used to measure the others
//
// Perturbation rule of the finite-difference methods (the seed's section 4.5
// problem): with integrator accuracy eps_int the computed psi carries an error
// of about eps_int |psi|, so a difference quotient has a noise error of about
// eps_int |psi| / delta and a truncation error of about delta |psi''| (forward)
// or delta^2 |psi'''| (central). Balancing the two gives
//   forward: delta_i = sqrt(eps)   * max(|b_i|, scale_i),
//   central: delta_i = cbrt(eps)   * max(|b_i|, scale_i),   eps = max(eps_int, 1e-15),
// so a looser integrator automatically gets a larger perturbation.
#include <memory>
#include <string>
#include <vector>

#include "vdyn/core/integrators.h"
#include "vdyn/core/registry.h"
#include "vdyn/sensitivity/cost.h"
#include "vdyn/sensitivity/design.h"

namespace vdyn {

/// What to differentiate: a model, the parameters (by name), a cost and a run.
struct SensitivityProblem {
  std::shared_ptr<const DesignModel> model;
  std::vector<std::string> parameters;  ///< names or seed symbols, see DesignModel::findParameter
  CostFunctional cost;
  double t_end_s = 1.0;                 ///< end of the cost horizon, s (runs start at the initial state's time)
  IntegratorSettings integrator;        ///< nominal (and perturbed) runs

  /// Throws Error naming the field if the model is missing, a parameter is
  /// unknown or repeated, t_end_s is not positive or the integrator is invalid.
  void validate() const;
  /// Indices of `parameters` in the model's parameter list.
  std::vector<int> parameterIndices() const;
};

/// How the mixed method adds coefficient nodes between passes.
enum class MixedRefinement {
  Uniform,   ///< every node interval longer than one nominal step is bisected
  Adaptive,  ///< only intervals whose interpolation indicator is >= 0.1 of the largest
};

/// "uniform" or "adaptive"; throws Error "<where>: expected uniform or
/// adaptive, got '<name>'".
MixedRefinement mixedRefinementFromName(const std::string& name, const std::string& where);

struct SensitivitySettings {
  /// Finite differences: relative perturbation delta_i / max(|b_i|, scale_i);
  /// 0 selects the rule above from the integrator accuracy.
  double perturbation = 0;
  /// mixed: relative tolerance on the error estimate of each d psi / d b_i
  /// (its change from the previous pass plus the Radau step-doubling estimate).
  double tolerance = 1e-5;
  /// mixed: which node intervals each pass bisects (the scene key
  /// "refinement": "uniform" | "adaptive").
  MixedRefinement refinement = MixedRefinement::Uniform;
  /// mixed: intervals of the coarsest coefficient grid over [0, T] (>= 3).
  int initial_intervals = 32;
  /// mixed: checked to lie in [2, 16], otherwise unused: the passes refine
  /// the nodes until the tolerance is met or every nominal step is a node.
  int max_levels = 9;
  /// reference: integrator accuracy and the larger relative perturbation (the
  /// second is half of it).
  double reference_accuracy = 1e-10;
  double reference_perturbation = 2e-3;
  /// reference: largest relative disagreement of the two perturbation sizes
  /// before the reference is refused (it measures errors down to about this).
  double reference_agreement = 1e-3;
};

struct SensitivityResult {
  std::string method;
  std::vector<std::string> parameters;  ///< key paths, in problem order
  double psi = 0;                       ///< cost at the nominal design
  std::vector<double> dpsi_db;          ///< d psi / d b_i, in problem order
  /// The method's own error estimate of each d psi / d b_i (absolute): the
  /// change from the previous pass plus the Radau step-doubling estimate
  /// (mixed), the disagreement of the two perturbation
  /// sizes (reference); empty for the plain finite differences.
  std::vector<double> error_estimate;
  std::vector<double> perturbation;     ///< delta_i used (finite differences), in the parameter's unit
  double wall_time_s = 0;
  int simulations = 0;                  ///< full time integrations
  // mixed only
  double nominal_wall_time_s = 0;       ///< the nominal integration within wall_time_s
  int grid_intervals = 0;               ///< coefficient node intervals of the last pass
  int integration_steps = 0;            ///< Radau IIA steps of the linear sensitivity system (last pass)
  int grid_points = 0;                  ///< points where the coefficient matrices were evaluated
  int residual_evaluations = 0;         ///< realizations for r_theta, r_theta', r_b
};

/// Base of the methods: compute() validates the problem and times DoCompute().
class SensitivityMethod {
 public:
  virtual ~SensitivityMethod() = default;
  const std::string& name() const { return name_; }
  const SensitivitySettings& settings() const { return settings_; }
  SensitivityResult compute(const SensitivityProblem& problem) const;

 protected:
  SensitivityMethod(std::string name, SensitivitySettings settings);
  virtual SensitivityResult DoCompute(const SensitivityProblem& problem) const = 0;

 private:
  std::string name_;
  SensitivitySettings settings_;
};

/// The built-in methods, in the order studies print them: "fd_forward",
/// "fd_central", "mixed", "reference".
const std::vector<std::string>& sensitivityMethodNames();
/// Registers the built-in methods in family "sensitivity_method" (Base
/// SensitivityMethod, context SensitivitySettings); an out-of-tree library adds
/// its own with registry.addChoice<SensitivityMethod, SensitivitySettings>(...).
void registerSensitivityMethods(PluginRegistry& registry);
/// The method registered as `name` (in `registry`, or the built-ins if
/// nullptr). Throws Error listing the known names if `name` is unknown.
std::unique_ptr<SensitivityMethod> makeSensitivityMethod(const std::string& name,
                                                         const SensitivitySettings& settings = {},
                                                         const PluginRegistry* registry = nullptr);

/// One simulation of the problem's model at design `b` (all parameters of the
/// model): builds the scene, adds the cost, makes the initial state, integrates
/// to t_end_s and returns psi.
double evaluateCost(const SensitivityProblem& problem, const std::vector<double>& b,
                    const IntegratorSettings& integrator);

/// The perturbation rule above: relative step for integrator accuracy `eps`.
double relativePerturbation(double eps, bool central);

}  // namespace vdyn
