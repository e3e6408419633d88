#pragma once
// Integrator choice by name: Simbody's six error-controlled integrators, and "auto":
//   auto                  RK Merson, switched by simulate() to CPodes from the
//                         step where RK Merson's steps are held by its
//                         stability limit (vdyn/core/stiffness.h); the run
//                         summary's integrator_choice says when and why
//   rk_merson             Runge-Kutta-Merson, 4th order (Simbody's default)
//   rk3                   Runge-Kutta 3rd order
//   rk_feldberg           Runge-Kutta-Fehlberg 4(5)
//   cpodes                CPodes variable-order BDF (implicit, for stiff scenes),
//                         driven by vdyn (vdyn/core/cpodes_stepper.h)
//   verlet                velocity Verlet, 2nd order with error estimate
//   semi_explicit_euler2  semi-explicit Euler with 2nd-order error estimate
#include <memory>
#include <string>
#include <vector>

#include <Simbody.h>

#include "vdyn/core/params.h"

namespace vdyn {

struct IntegratorSettings {
  std::string method = "rk_merson";
  /// Relative accuracy of the integration (dimensionless), in (0, 1).
  double accuracy = 1e-6;
  /// Tolerance on constraint errors (position: m for loop closures; velocity: m/s).
  double constraint_tolerance = 1e-10;
  /// Largest step the integrator may take, s; 0 = no limit.
  double max_step_s = 0.0;

  void validate() const;
  /// Keys: method, accuracy, constraint_tolerance, max_step_s (all optional).
  static IntegratorSettings fromParams(const ParamReader& r, IntegratorSettings defaults);
  static IntegratorSettings fromParams(const ParamReader& r);
};

/// Names accepted by makeIntegrator, in a fixed order.
const std::vector<std::string>& integratorNames();

/// Issue 12 item 4: where a method's error estimate is known not to bound the
/// error of vdyn's vehicle scenes, a one-line caveat saying so (with the
/// measured figure), else "". The figures are the stress matrix's
/// (build/bin/stress: error of the final yaw rate or cost against an
/// rk_merson 1e-9 reference, over the accuracy asked for; see docs/benchmarks.md,
/// "Stress matrix"). simulate() puts the caveat into RunSummary::warnings and
/// prints it once per process on stderr.
std::string errorEstimateCaveat(const IntegratorSettings& settings);

/// Creates Simbody's integrator for `settings.method` (auto: RK Merson);
/// throws Error naming the method if it is unknown, and for "cpodes", which
/// simulate() runs through CpodesStepper (vdyn/core/cpodes_stepper.h).
std::unique_ptr<SimTK::Integrator> makeIntegrator(const SimTK::System& system,
                                                  const IntegratorSettings& settings);

}  // namespace vdyn
