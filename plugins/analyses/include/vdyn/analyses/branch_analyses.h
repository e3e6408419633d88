#pragma once
// The two registered analyses that follow a branch of steady states, with the
// per-point results a chapter program tabulates: continuation (steady_sweep)
// and optimal_ratio (ch6_steering_ratio). A study builds the scene from its
// scene file (SceneDescription::build), takes the analysis the scene made
// (fromScene), calls follow() for the points and summarize() for the summary
// keys `vdyn run` writes: one code path for the study and the scene, so their
// numbers agree bit for bit (SceneEquality.* ctests).
#include <string>
#include <vector>

#include "vdyn/core/analysis.h"
#include "vdyn/core/scene_file.h"
#include "vdyn/steady_state/steady_state.h"
#include "vdyn/steering_ratio/steering_ratio.h"

namespace vdyn {

/// A steady-state point of a continuation branch, with its stability verdict.
struct BranchPoint {
  double value = 0;             ///< the driving value (the "key"'s unit)
  bool converged = false;
  std::string failure;          ///< why not converged (solver message, branch refusal or end)
  /// "stable", "unstable" (verdict computed), "converged" (no verdict asked),
  /// "branch_jump_refused", "beyond_branch_end", "no_steady_state".
  std::string status;
  SteadyStateResult result;     ///< valid when converged
  bool stability_checked = false;
  StabilityResult stability;    ///< valid when stability_checked
};

struct BranchRun {
  std::vector<BranchPoint> points;  ///< one per "values" entry (lead values not included)
  double solve_wall_time_s = 0, stability_wall_time_s = 0;
  /// When a point failed after a converged one: pseudo-arclength continuation
  /// (continueSteadyState) from the last converged point towards the failed
  /// value, through the fold and past_fold_points beyond it. "limit" of the
  /// summary: {"fold": {value, lateral_acceleration_m_s2, eigenvalues,
  /// located, bracket, location_iterations, outputs} or null, "hopf": [...],
  /// "points": [...], steps, rejected_steps, corrector_iterations,
  /// stop_reason[, failure]}; null when the branch did not end.
  Json limit;
  double fold_value = 0;  ///< the fold's value when limit.fold is not null (key's unit)
  bool has_fold = false;
  /// Rows of the arclength table (value, arclength, stable, least-damped
  /// eigenvalue, lateral acceleration, outputs).
  std::vector<std::vector<double>> limit_rows;
};

/// "analysis": {"type": "continuation", ...}: the steady state as a plugin's
/// adjustable (a speed, a held steering angle) takes values in turn.
class ContinuationAnalysis : public Analysis {
 public:
  struct Settings {
    std::string chassis = "chassis";
    std::vector<std::string> wheels;  ///< empty: the vehicle's "wheels" attachment
    double time_s = 0;
    double force_tolerance_N = 1e-6;
    int max_iterations = 60;
    std::vector<double> values, lead_values;
    std::string plugin, key;
    std::vector<std::string> also_plugins;
    std::vector<double> also_scales;
    std::vector<std::string> table_outputs;
    bool stability = false;
    int max_bisections = 4;
    std::string branch_output;          ///< "": no branch check
    double branch_max_change_factor = 2;
    int past_fold_points = 3;           ///< arclength points continued past the fold
    double fold_tolerance = 1e-7;       ///< bracket length of the located fold / Hopf point, key's unit
  };
  explicit ContinuationAnalysis(const ParamReader& settings);
  const Settings& settings() const { return s_; }
  /// The analysis `built` made from its scene's "analysis" (throws Error if
  /// that is not a continuation).
  static const ContinuationAnalysis& fromScene(const BuiltScene& built);
  /// Follows the branch from the built scene's initial state: the lead values
  /// (the first must converge: Error otherwise), then the values, each point
  /// with the stability verdict if "stability".
  BranchRun follow(const BuiltScene& built) const;
  /// The summary keys: "points" (per point), "total_points", "converged_points",
  /// "stable_points", "unstable_points", "no_steady_state_points",
  /// "branch_jumps_refused", "median_iterations_per_point",
  /// "max_iterations_per_point" (-1 without a converged point),
  /// "largest_stable_value" (0 if none), "branch_labels" (where stability
  /// changes or the branch is refused: {from_value, to_value, label[, reason]}).
  Json summarize(const BuiltScene& built, const BranchRun& run) const;

 protected:
  AnalysisResult DoRun(const AnalysisContext& ctx) const override;

 private:
  /// Pseudo-arclength continuation from `last` (converged at vLast) towards
  /// vFail (failed): BranchRun::limit, fold_value, has_fold, limit_rows.
  Json followLimit(const BuiltScene& built, SteadyStateSolver& solver, const SteadyStateResult& last, double vLast,
                   double vFail, const std::function<void(SimTK::State&, double)>& setValue, BranchRun& run) const;
  Settings s_;
};

struct OptimalRatioRun {
  double speed_m_s = 0;
  double kr_start = 0;                  ///< first guess of Kr at the first angle
  std::vector<OptimalRatioPoint> points;
};

/// "analysis": {"type": "optimal_ratio", ...}: the 4WS ratio Kr of zero steady
/// side slip over front angles at the scene's speed (6.12)-(6.15) and the fit (8.1).
class OptimalRatioAnalysis : public Analysis {
 public:
  struct Settings {
    std::string front_plugin = "front_steer", rear_plugin = "rear_steer";
    std::string chassis = "chassis";
    std::vector<std::string> wheels;
    std::vector<double> front_angles_rad;
    double kr_start = 0;
    bool linear_start = false;
    LinearBicycleParams linear;
    OptimalRatioOptions options;
    SteadyStateOptions solver;
  };
  explicit OptimalRatioAnalysis(const ParamReader& settings);
  const Settings& settings() const { return s_; }
  static const OptimalRatioAnalysis& fromScene(const BuiltScene& built);
  /// The branch at the built scene's speed over `front_angles_rad` (ascending,
  /// > 0), or the settings' angles if null.
  OptimalRatioRun follow(const BuiltScene& built, const std::vector<double>* front_angles_rad = nullptr) const;
  /// The summary keys: "speed_m_s", "kr_start", "linear_kr" (with
  /// linear_bicycle), "points" (per point), "map_points" (with a steady state),
  /// "infeasible_points" (least side slip), "largest_front_deg" (last point with
  /// a steady state), "steady_state_solves", "newton_iterations",
  /// "kr_iterations", and "fit" {speed_m_s, c1, c2_per_deg2, rms_residual,
  /// points, infeasible_points} when two or more points have zero side slip.
  Json summarize(const OptimalRatioRun& run) const;

 protected:
  AnalysisResult DoRun(const AnalysisContext& ctx) const override;

 private:
  Settings s_;
};

}  // namespace vdyn
