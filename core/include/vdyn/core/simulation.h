#pragma once
// Time integration of a finalized Scene with run statistics.
#include <functional>
#include <string>
#include <vector>

#include "vdyn/core/integrators.h"
#include "vdyn/core/recorder.h"
#include "vdyn/core/scene.h"

namespace vdyn {

struct SimulationSettings {
  /// End time of the run, s (absolute, not a duration).
  double t_end_s = 1.0;
  /// Interval between recorder samples, s; samples are interpolated, never forced steps.
  double report_interval_s = 0.01;
  IntegratorSettings integrator;

  // Run guards: simulate() never hangs silently. Each limit ends the run with a
  // vdyn::Error that names the guard, the time reached and a state summary.
  /// Largest number of attempted integrator steps (accepted + rejected); 0 = no limit.
  long max_steps = 2000000;
  /// Smallest accepted step, s: `min_step_count` consecutive accepted steps
  /// shorter than this end the run (the step size has collapsed); 0 = no check.
  double min_step_s = 1e-9;
  int min_step_count = 200;
  /// Wall-clock budget of the run, s; 0 = none.
  double wall_time_budget_s = 0;
  /// Largest number of recorder samples (t_end - t0) / report_interval_s.
  long max_samples = 10000000;
  /// Progress: called about every `progress_interval_s` of wall time with the
  /// advanced state (empty: no progress). Studies print a line with it.
  double progress_interval_s = 0;
  std::function<void(const SimTK::State&, double wall_s)> progress;

  /// Times (s, absolute) where an input's rate jumps (a steering profile
  /// that is only C0, Plugin::calcInputJumpTimes): the integrator stops there
  /// and restarts from the right (its initialisation projects the velocities
  /// onto the new rate). Those outside (start, t_end_s) are ignored; the
  /// report grid continues across them; the summary counts every segment.
  std::vector<double> restart_times_s;

  void validate() const;
};

struct RunSummary {
  std::string integrator;  ///< as asked for (settings.integrator.method)
  /// With the integrator "auto": which methods ran, from when, and why (the
  /// steps against RK Merson's stability limit at the last check); else "".
  std::string integrator_choice;
  double accuracy = 0;
  int steps = 0;              ///< accepted integrator steps
  int attempts = 0;           ///< attempted steps (accepted + rejected)
  int realizations = 0;       ///< full realizations of the system (cost driver)
  int projections = 0;        ///< constraint projections
  /// Jacobians of y' = f(t, y) by differences (the integrator "auto"'s
  /// stiffness checks, CPodes's Newton matrices), whose evaluations are
  /// among the realizations (n or n + 1 each, n the number of states).
  int jacobians = 0;
  /// Largest position-constraint error |qerr|_inf at the end of any step (m for
  /// loop closures, dimensionless for angle constraints).
  double max_constraint_error = 0;
  double sim_time_s = 0;      ///< simulated time
  double wall_time_s = 0;     ///< wall-clock time of the integration
  /// Caveats about the run's figures, one line each (errorEstimateCaveat():
  /// an integrator whose error estimate does not bound the error here).
  std::vector<std::string> warnings;
};

/// One line describing where a run is: time, and where the scene has them the
/// chassis position, speed, yaw rate and side slip; else the largest |q| and |u|.
std::string stateSummary(const Scene& scene, const SimTK::State& state);

/// Largest position-constraint error of a state realized through Position.
double positionConstraintError(const SimTK::State& state);

/// Advances `state` (initial in, final out) to settings.t_end_s. Every cost
/// integral (Scene::addIntegralOfSquare) starts the run at zero: Simbody's
/// Integrator::initialize restarts each Measure::Integrate from its initial value. If `recorder`
/// is given it samples at the start and every report interval. `afterStep` is
/// called with the advanced state after every accepted step. Integration
/// failures are rethrown as Error naming the time and the integrator; the run
/// guards of `settings` (max_steps, min_step_s, wall_time_budget_s, max_samples)
/// end a run that would not finish with an Error naming the guard, the time
/// and a state summary (stateSummary()). If `partial` is given and the run
/// ends by an exception (a guard, an integration failure, Interrupted, or
/// whatever `afterStep` throws), *partial holds the counts up to the last
/// accepted step before it propagates: steps, attempts, realizations,
/// projections, max_constraint_error, sim_time_s (from the start to that
/// step) and wall_time_s; on success it is the summary returned.
RunSummary simulate(const Scene& scene, SimTK::State& state, const SimulationSettings& settings,
                    Recorder* recorder = nullptr,
                    const std::function<void(const SimTK::State&)>& afterStep = {},
                    RunSummary* partial = nullptr);

}  // namespace vdyn
