#pragma once
// The built-in analyses a scene file names by "analysis": {"type": ...}, and
// the reusable pieces the chapter programs compose from (runTransient).
//
//   transient           integrate the scene (simulate) and report final values,
//                       peaks, cost integrals and the run's statistics
//   static_equilibrium  solveStaticEquilibrium at zero speed
//   steady_state        SteadyStateSolver on the chassis turning problem
//   continuation        followSteadyState over speed or a steering angle
//   stability           linearised eigenvalues at the steady state
//   sensitivity         d cost / d parameters, parameters = key paths of the scene
//   optimal_ratio       nonlinear optimal 4WS ratio Kr(delta_f) at the scene's speed
#include <string>
#include <vector>

#include "vdyn/core/analysis.h"
#include "vdyn/core/events.h"
#include "vdyn/core/fields.h"
#include "vdyn/core/recorder.h"
#include "vdyn/core/registry.h"
#include "vdyn/core/scene_file.h"
#include "vdyn/core/simulation.h"
#include "vdyn/sensitivity/design.h"

namespace vdyn {

/// Settings of the transient analysis (keys of the scene's "analysis" object).
struct TransientSettings {
  double t_end_s = 1.0;               ///< end time, s
  double report_interval_s = 0.01;    ///< sampling interval of the recorded outputs, s (0 = none)
  IntegratorSettings integrator;      ///< "integrator": {method, accuracy, constraint_tolerance, max_step_s}
  /// Outputs y whose int_0^T y^2 dt is carried as an error-controlled state (seed 4.46).
  std::vector<std::string> integrals_of_square;
  bool write_history = true;          ///< write history.csv of the recorded outputs
  /// Wall-clock budget of the run, s (0 = none): beyond it simulate() stops
  /// with a named error saying where (SimulationSettings::wall_time_budget_s).
  double wall_time_budget_s = 0;
  /// Regime guards ("events": {...}, core/events.h): spin-out, rollover,
  /// lift-off and leaving the path are recorded with their time and value in
  /// the summary's "events"; none ends the run unless "fatal" lists it.
  EventLimits events = EventLimits::recordOnly();

  static const FieldTable<TransientSettings>& fields();
  SimulationSettings simulation() const;
};

/// A finished transient run.
struct TransientRun {
  SimTK::State final_state;
  RunSummary run;
  std::unique_ptr<Recorder> recorder;      ///< the scene's "outputs" sampled every report interval
  std::vector<double> integrals;           ///< one per TransientSettings::integrals_of_square
  Json vehicle;                            ///< Vehicle::describe at the initial state
  std::vector<Event> events;               ///< the regime events of the run (TransientSettings::events)
};

/// Runs the built scene from its initial state to settings.t_end_s, recording
/// `built.outputs`. `progress` may be empty; `observer`, if given, gets each
/// sample's state (an animation's recorder). The one transient run the
/// transient analysis and the chapter programs share.
TransientRun runTransient(BuiltScene& built, const TransientSettings& settings, const ProgressFactory& progress = {},
                          const SampleObserver& observer = {});

/// The transient analysis's summary of a run: "final" (every scene output at
/// the end), "peak_abs" (largest |value| of each recorded output), "rms" (root
/// mean square over the samples of each recorded output), "integrals",
/// "run" (steps, realizations, max_constraint_error, wall_time_s, ...) and "vehicle".
Json summarizeTransient(const BuiltScene& built, const TransientSettings& settings, const TransientRun& r);

/// The design model of a scene (chapter 4): parameters are key paths of the
/// scene; "vehicle.data.<path>" names a value of the vehicle data file (set
/// through vehicle.overrides). Each design builds a fresh scene from the
/// description with the values as overrides.
class SceneDesign : public DesignModel {
 public:
  SceneDesign(const SceneDescription& scene, const std::vector<DesignParameter>& params);
  /// Parameters named apart from where they live: params[i] is the value at
  /// scene key path keyPaths[i]. `heldData` (a merge patch over the vehicle
  /// data, e.g. Vehicle::derivedData() of the nominal design) is applied to
  /// every design before the parameters: values the vehicle derives from a
  /// rule are then data (a datum) held at their nominal values.
  SceneDesign(const SceneDescription& scene, const std::vector<DesignParameter>& params,
              std::vector<std::string> keyPaths, const Json& heldData);
  /// The design model a sensitivity analysis of the scene differentiates: the
  /// scene's "analysis" (type sensitivity) with its "parameters" (key paths,
  /// or objects {"path", "name", "symbol", "unit", "scale"}), "scales" and
  /// "derived_data" (nominal: builds the nominal scene once and holds what
  /// its vehicle derived). Throws Error naming the key.
  static std::shared_ptr<SceneDesign> fromAnalysis(const SceneDescription& scene);
  /// Parameters at the scene's nominal values (scale = |nominal|, or 1 if 0);
  /// throws Error naming a path that is not a number in the scene or data file.
  static std::vector<DesignParameter> parametersOf(const SceneDescription& scene,
                                                   const std::vector<std::string>& keyPaths);
  std::string describe() const override { return "scene '" + scene_.name() + "'"; }
  /// The scene key path of each parameter (getParameters() order).
  const std::vector<std::string>& keyPaths() const { return paths_; }

 protected:
  std::unique_ptr<DesignInstance> DoBuild(const std::vector<double>& values) const override;

 private:
  SceneDescription scene_;
  std::vector<std::string> paths_;
  std::vector<Override> held_;
};

/// Registers every built-in analysis.
void registerAnalyses(PluginRegistry& registry);

}  // namespace vdyn
