#pragma once
// The integrator "cpodes" (vdyn/core/integrators.h): Simbody's SimTK::CPodes
// (SUNDIALS CPODES: variable-order BDF, Newton iterations, dense LAPACK
// factorization) driven directly on a System's first-order equations
// y' = f(t, y), y = (q, u, z) in Simbody's order, instead of through
// SimTK::CPodesIntegrator. The same method and error control (relative
// tolerance = accuracy, absolute = accuracy / 10, scalar; Newton
// convergence coefficient 0.01; positions and velocities projected onto the
// constraints after every step by Simbody's own projection), with three
// differences that cost evaluations there (docs/benchmarks.md, "Against MuJoCo"):
//  - a step's end is not realized through Acceleration (CPodes's last
//    evaluation is at its last Newton iterate); whoever needs the
//    accelerations there realizes them;
//  - the Newton matrix's Jacobian is computed here, by forward differences
//    with the increments of calcStateDerivativeJacobian (vdyn/core/stiffness.h),
//    n evaluations (CPodes hands over f(y)); and the first one can be handed
//    in (the integrator "auto"'s stiffness check has it, at the same state);
//  - report times are interpolated with CPodes's own polynomial (getDky)
//    inside the step that passed them, never stepped to.
//
// SimTK::CPodes::dlsSetJacFn takes SUNDIALS's C callback; SUNDIALS's headers
// are not installed with Simbody, so the two layouts the callback reads (an
// N_Vector over a SimTK::Vector, and the dense DlsMat) are mirrored from
// Simbody 3.7's bundled CPODES in cpodes_stepper.cpp, and checked there at
// every call (sizes, matrix type) and by the tests (a linear system's
// Jacobian and solution in closed form).
#include <memory>
#include <string>

#include <Eigen/Dense>
#include <Simbody.h>

#include "vdyn/core/integrators.h"

namespace vdyn {

class CpodesStepper {
 public:
  /// `settings`: accuracy, constraint_tolerance and max_step_s are used
  /// (its method is not read).
  CpodesStepper(const SimTK::System& system, const IntegratorSettings& settings);
  ~CpodesStepper();
  CpodesStepper(const CpodesStepper&) = delete;
  CpodesStepper& operator=(const CpodesStepper&) = delete;

  /// Starts at `state` (projected onto the constraints first; one evaluation).
  /// `jacobian` (optional, n x n, n = state.getNY()): df/dy at this state,
  /// taken for the first Newton matrix instead of computing one.
  /// Throws Error if CPodes cannot start.
  void initialize(const SimTK::State& state, const Eigen::MatrixXd* jacobian = nullptr);
  /// The time CPodes must not step past (s); without one, step() takes
  /// CPodes's steps with no bound.
  void setFinalTime(double t);
  /// One internal step, not past the final time; returns true when the
  /// final time is reached. Throws Error (with CPodes's reason and the
  /// time) if CPodes fails.
  bool step();

  /// The state at the end of the last step: time, y (CPodes's, or its
  /// projection's to rounding), realized through Velocity (not Acceleration).
  const SimTK::State& getState() const { return state_; }
  /// y at time t in [end of the previous step, end of the last step], from
  /// CPodes's interpolating polynomial (not projected), into `y`.
  void interpolate(double t, SimTK::Vector& y) const;

  double getTime() const { return state_.getTime(); }
  double getPreviousStepSizeTaken() const;
  long getNumStepsTaken() const;
  /// Steps taken plus those rejected (error test or Newton convergence failures).
  long getNumStepsAttempted() const;
  /// Forward-dynamics evaluations (realizations through Acceleration):
  /// CPodes's f evaluations and the Jacobians' columns.
  long getNumRealizations() const { return evaluations_; }
  long getNumJacobians() const { return jacobians_; }
  long getNumProjections() const { return projections_; }

 private:
  class Ode;
  friend class Ode;
  static int jacobianCallback(int n, double t, void* y, void* fy, void* jac, void* self, void*, void*, void*);
  void throwIfFailed(int flag, const std::string& doing) const;
  void setMinStep();
  /// work_ at (t, y), prescribed q applied, realized through Position.
  void setWork(double t, const SimTK::Vector& y);
  /// f(t, y) in work_ (prescribed q and u applied), counted.
  const SimTK::Vector& evaluate(double t, const SimTK::Vector& y);

  const SimTK::System& system_;
  IntegratorSettings settings_;
  std::unique_ptr<Ode> ode_;
  std::unique_ptr<SimTK::CPodes> cpodes_;
  SimTK::State state_;      // the last step's end
  SimTK::State work_;       // where f and the Jacobian's columns are evaluated
  SimTK::Vector y_, yp_;    // CPodes's y and y' at the last step's end
  Eigen::MatrixXd handedJacobian_;  // for CPodes's first Jacobian (empty: none, or used)
  double finalTime_ = SimTK::Infinity;
  long evaluations_ = 0, jacobians_ = 0, projections_ = 0;
  std::string callbackError_;  // the exception a callback caught, for the message
  std::string cpodesMessage_;  // CPodes's own last error message
};

}  // namespace vdyn
