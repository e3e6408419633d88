#pragma once
// Time integration of a finalized Scene with run statistics.
#include <functional>
#include <string>

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

  void validate() const;
};

struct RunSummary {
  std::string integrator;
  double accuracy = 0;
  int steps = 0;              ///< accepted integrator steps
  int attempts = 0;           ///< attempted steps (accepted + rejected)
  int realizations = 0;       ///< full realizations of the system (cost driver)
  int projections = 0;        ///< constraint projections
  /// Largest position-constraint error |qerr|_inf at the end of any step (m for
  /// loop closures, dimensionless for angle constraints).
  double max_constraint_error = 0;
  double sim_time_s = 0;      ///< simulated time
  double wall_time_s = 0;     ///< wall-clock time of the integration
};

/// Largest position-constraint error of a state realized through Position.
double positionConstraintError(const SimTK::State& state);

/// Advances `state` (initial in, final out) to settings.t_end_s. Every cost
/// integral (Scene::addIntegralOfSquare) starts the run at zero: Simbody's
/// Integrator::initialize restarts each Measure::Integrate from its initial value. If `recorder`
/// is given it samples at the start and every report interval. `afterStep` is
/// called with the advanced state after every accepted step. Integration
/// failures are rethrown as Error naming the time and the integrator.
RunSummary simulate(const Scene& scene, SimTK::State& state, const SimulationSettings& settings,
                    Recorder* recorder = nullptr,
                    const std::function<void(const SimTK::State&)>& afterStep = {});

}  // namespace vdyn
