#pragma once
// The seed's general steady-state analysis (chapter 3, docs/equations.md "Steady state") on a
// Simbody scene, its continuation, stability verdict and sensitivity.
//
// The state is split into zero, ineffective and effective variables by a
// SteadyStateProblem that the vehicle and manoeuvre declare (the solver knows no
// vehicle). In the Euler-angle form of the state (every mobilizer has nq = nu),
// the unknowns are
//     x = [ q_e (effective coordinates), u_e (effective speeds),
//           lambda (multipliers of every constraint), z (auxiliary states) ]
// and the equations are
//     f(q, u) - M udot_s(q, u) - G^T lambda = 0   every mobility    (3.9)-(3.11)
//     Psi(q) = 0                                   position constraints (3.12)
//     nonholonomic velocity constraints, e.g. the speed (3.18)
//     zdot = 0                                      auxiliary states (tire lag)
// with udot_s the accelerations of steady motion, functions of the velocities
// (3.19). f - M udot_s is Simbody's inverse dynamics
// (calcResidualForceIgnoringConstraints): no forward dynamics is needed. Zero
// variables (u not listed as effective) are held at 0; ineffective coordinates
// keep their values. Newton-Raphson with a finite-difference Jacobian
// (3.15)-(3.17) (columns of lambda are exact: -G^T), rank-one (Broyden) updates
// between fresh Jacobians, and a backtracking line search on a scaled merit.
#include <complex>
#include <functional>
#include <limits>
#include <string>
#include <vector>

#include <Eigen/Dense>
#include <Simbody.h>

#include "vdyn/core/error.h"
#include "vdyn/core/scene.h"
#include "vdyn/steady_state/arclength.h"

namespace vdyn {

/// A model parameter solved for as an extra unknown (e.g. the held steering
/// angle of a constant-radius test). It is not a state variable: set() changes
/// the model (e.g. HoldCommand::setAngle) and the solver re-realizes from
/// Stage::Position after every change.
struct SteadyStateParameter {
  std::string name;        ///< for messages, e.g. "front steering angle (rad)"
  double typical = 0.01;   ///< typical size, in the parameter's unit (finite-difference step scale)
  std::function<double(const SimTK::State&)> get;
  std::function<void(SimTK::State&, double)> set;
};

/// An extra equation c(state) = 0, one per extra unknown (e.g. the speed
/// relation U - r R = 0 of a constant-radius test).
struct SteadyStateCondition {
  std::string name;        ///< for messages, e.g. "path radius: r R - U (m/s)"
  double tolerance = 1e-12;  ///< converged when |c| <= tolerance, unit of c
  double weight = 1e4;     ///< merit weight: newtons per unit of c
  /// c on a state realized to Stage::Velocity.
  std::function<double(const SimTK::State&)> calc;
};

/// Declared by the vehicle / manoeuvre. Indices refer to the Euler-angle state
/// (SimbodyMatterSubsystem::convertToEulerAngles), where nq == nu.
struct SteadyStateProblem {
  /// Time at which time-dependent inputs (steering commands, road) are
  /// evaluated, s: a time after every command has settled.
  double time_s = 0;
  /// Ineffective coordinates: q indices that keep their values (e.g. the
  /// chassis x, y, yaw and the wheel spin angles).
  std::vector<int> ineffective_q;
  /// Effective generalized speeds (unknowns); every other u is a zero variable.
  std::vector<int> effective_u;
  /// Mobilities whose equations are checked at the solution, not solved:
  /// a static equilibrium (makeRestProblem) holds every speed at zero, so the
  /// ineffective coordinates (chassis x, y, yaw, wheel spins) have no unknown
  /// left; their generalized forces (the tires' in-plane forces at zero slip)
  /// must vanish on their own, to the force tolerance, or solve() throws
  /// naming the equation. u indices; effective q + effective u + these = nu.
  std::vector<int> checked_u;
  /// Steady accelerations udot_s(q, u) (3.19), given Stage::Velocity; all zero
  /// when empty.
  std::function<void(const SimTK::State&, SimTK::Vector& udot)> calc_steady_udot;
  /// A free-mobilizer base whose yaw and horizontal position the dynamics do
  /// not depend on (flat road). The stability analysis linearises in a frame
  /// that turns with it; invalid = no such symmetry.
  SimTK::MobilizedBodyIndex floating_base;
  /// Coordinates the stability analysis leaves out besides the base's x, y and
  /// yaw: ones no force depends on (wheel spin angles). Euler-state q indices.
  std::vector<int> cyclic_q;
  /// Extra unknowns (model parameters) and as many extra equations: e.g. the
  /// steering angle and the path-radius relation U = r R (ISO 4138 constant
  /// radius), or the steering angle and a lateral acceleration U r = a_y.
  std::vector<SteadyStateParameter> parameters;
  std::vector<SteadyStateCondition> conditions;
};

/// A steady turn of a vehicle with a free-mobilizer chassis on a flat road:
/// ineffective chassis x, y, yaw (the third body-XYZ angle) and wheel spin
/// angles; effective chassis yaw rate, horizontal velocity and wheel spin rates;
/// every other speed zero; chassis acceleration w x v (3.19).
SteadyStateProblem makeSteadyTurningProblem(const Scene& scene, const std::string& chassisBody,
                                            const std::vector<std::string>& wheelBodies, double time_s);

/// The static equilibrium at rest of the same vehicle: every speed held at
/// zero (zero variables), the coordinates other than the chassis x, y, yaw and
/// the wheel spin angles solved (and the constraint multipliers); the
/// equations of those ineffective coordinates are checked, not solved
/// (SteadyStateProblem::checked_u). As a steady turn at zero speed the speeds
/// were unknowns too, and free rolling (chassis x velocity U, every wheel
/// spin U / R) solved them at any U: a singular Jacobian.
SteadyStateProblem makeRestProblem(const Scene& scene, const std::string& chassisBody,
                                   const std::vector<std::string>& wheelBodies, double time_s);

struct SteadyStateOptions {
  double force_tolerance = 1e-6;       ///< max |generalized-force residual|, N or N m
  double position_tolerance = 1e-12;   ///< max |position-constraint error|, m or rad
  double velocity_tolerance = 1e-12;   ///< max |velocity-constraint error|, m/s
  double rate_tolerance = 1e-12;       ///< max |zdot| (units of z per second)
  int max_iterations = 60;
  /// Rank-one updates between finite-difference Jacobians (far fewer residual
  /// evaluations); a fresh Jacobian is taken whenever a step fails to descend.
  bool broyden = true;
  /// Start every solve (also resolve() in a continuation) with a fresh
  /// Jacobian: Newton's quadratic convergence from a good start (2-4
  /// iterations) for ~n extra residual evaluations. Off: the previous solve's
  /// updated Jacobian is reused (fewer evaluations, more iterations).
  bool fresh_jacobian_each_solve = true;
};

/// Thrown when the solver does not converge: the message names the iterations,
/// the residual norms and the worst equation.
class SteadyStateError : public Error {
 public:
  using Error::Error;
};

struct SteadyStateResult {
  /// The steady state (quaternion form), realized to Velocity. A copy of a
  /// State loses its realized stages: realize a copy (or use
  /// Scene::evalOutput, which does) before reading kinematics from it.
  SimTK::State state;
  SimTK::State euler_state;        ///< the same in Euler-angle form (restart point)
  int iterations = 0;              ///< Newton iterations
  int jacobians = 0;               ///< finite-difference Jacobians taken
  int residual_evaluations = 0;
  double force_residual = 0;       ///< max |f - M udot_s - G^T lambda|, N (checked equations included)
  double position_error = 0;       ///< max |Psi|
  double velocity_error = 0;       ///< max |nonholonomic error|
  double rate_residual = 0;        ///< max |zdot|
  double residual_norm = 0;        ///< scaled 2-norm of all equations
  SimTK::Vector multipliers;       ///< lambda (Simbody's order and sign)
  /// Values of the problem's extra unknowns (SteadyStateProblem::parameters),
  /// in their order; the model is left set to them.
  std::vector<double> parameters;
  double condition_residual = 0;   ///< max |extra condition| (its own unit)
  double wall_time_s = 0;
};

struct StabilityResult {
  bool stable = false;
  /// The eigenvalue with the largest real part (1/s): its real part is the
  /// slowest decay rate (or growth, if > 0).
  std::complex<double> least_damped;
  std::vector<std::complex<double>> eigenvalues;
  int dimension = 0;               ///< independent states linearised
  double equilibrium_residual = 0; ///< max |reduced state rate| at the point (should be ~0)
};

/// An input of the linearisation (e.g. a steering command): set(state, v,
/// v', v'') applies the input's deviation v from its steady value and its
/// first two time derivatives to the model (the steering command's angle,
/// rate and acceleration); the solver re-realizes from Stage::Position.
struct LinearInput {
  std::string name;
  double typical = 1e-3;  ///< finite-difference step scale, unit of the input
  std::function<void(SimTK::State&, double v, double vdot, double vddot)> set;
};

/// An output of the linearisation, evaluated on a state whose floating base
/// has zero yaw (so ground x is the heading, ground y its left), realized to
/// Stage::Acceleration.
struct LinearOutput {
  std::string name;
  std::function<double(const SimTK::State&)> calc;
};

/// The equations of motion linearised about a steady state on the constraint
/// manifold, in D independent coordinates xi (tangent directions):
///     xi' = A xi + B0 v + B1 v' + B2 v''
///     y   = C xi + D0 v + D1 v' + D2 v''   (deviations from the steady state)
/// Inputs that move the constraints (a commanded steering angle and its rate)
/// carry their particular state displacement into B0, B1, D0, D1; the
/// commanded acceleration enters the acceleration-level constraint (B2, D2).
struct LinearModel {
  Eigen::MatrixXd A, B0, B1, B2, C, D0, D1, D2;
  std::vector<std::string> inputs, outputs;
  /// Frequency response y/v at omega (rad/s): C (j w I - A)^-1 (B0 + j w B1 -
  /// w^2 B2) + D0 + j w D1 - w^2 D2 (outputs x inputs).
  Eigen::MatrixXcd calcResponse(double omega_rad_s) const;
};

class SteadyStateSolver {
 public:
  SteadyStateSolver(const Scene& scene, SteadyStateProblem problem, SteadyStateOptions options = {});

  /// Solves from `guess` (any state of the scene; its velocities and
  /// coordinates are the start). Throws SteadyStateError if it does not converge.
  SteadyStateResult solve(const SimTK::State& guess);
  /// Re-solves from a previous result (e.g. after a condition changed); keeps
  /// the last Jacobian as the first one when Broyden updates are on.
  SteadyStateResult resolve(const SteadyStateResult& previous);
  /// Forces a fresh finite-difference Jacobian at the next solve.
  void invalidateJacobian() { haveJacobian_ = false; }

  /// Linearises the equations of motion about a steady state (central finite
  /// differences of Simbody's forward dynamics) on the constraint manifold, in
  /// the frame turning with the floating base, and returns the eigenvalues.
  /// Stable when every real part is below -tolerance_per_s.
  StabilityResult calcStability(const SteadyStateResult& steady, double tolerance_per_s = 1e-6) const;
  /// The same linearisation with input columns and output rows (central
  /// differences; steps 1e-6 of the state's tangent directions and
  /// 1e-3 x typical of each input). calcStability's A is this A.
  LinearModel calcLinearModel(const SteadyStateResult& steady, const std::vector<LinearInput>& inputs,
                              const std::vector<LinearOutput>& outputs) const;

  const SteadyStateProblem& problem() const { return problem_; }
  const SteadyStateOptions& options() const { return opt_; }
  SteadyStateOptions& updOptions() { return opt_; }

  /// Unknowns of the Euler-angle state `se` with multipliers `lambda` (extra
  /// parameters as the model holds them now), and back.
  Eigen::VectorXd getUnknowns(const SimTK::State& se, const SimTK::Vector& lambda) const;
  /// Unknowns of a result (its euler_state, multipliers and parameters).
  Eigen::VectorXd getUnknowns(const SteadyStateResult& r) const;
  /// Writes unknowns x into a result used as a start for resolve().
  void setGuess(const Eigen::VectorXd& x, SteadyStateResult& guess) const;
  /// The equations at unknowns x, unscaled (for tests).
  Eigen::VectorXd calcEquations(const Eigen::VectorXd& x) const;
  int numUnknowns() const { return n_; }

  /// Pseudo-arclength continuation in a driving condition lambda (a held
  /// steering angle, a held speed) that `drive(state, lambda)` applies to a
  /// state's model (continueSteadyState). beginDriven takes the start's
  /// model and time into the workspace; then calcDrivenEquations gives
  /// F(x; lambda), calcDrivenJacobian [dF/dx, dF/dlambda] (n x (n + 1),
  /// forward differences, lambda's step 1.5e-8 max(|lambda|, lambda_scale)),
  /// and makeDrivenResult the steady state at a solution (the model left set
  /// to lambda).
  void beginDriven(const SteadyStateResult& start, std::function<void(SimTK::State&, double)> drive,
                   double lambda_scale);
  Eigen::VectorXd calcDrivenEquations(const Eigen::VectorXd& x, double lambda) const;
  Eigen::MatrixXd calcDrivenJacobian(const Eigen::VectorXd& x, double lambda, const Eigen::VectorXd& r) const;
  SteadyStateResult makeDrivenResult(const Eigen::VectorXd& x, double lambda) const;
  /// The Euler-angle state at (x, lambda) (a copy of the workspace, lambda's
  /// model left set): what an output of a point needs, without the
  /// quaternion form's conversion or a residual evaluation.
  SimTK::State getDrivenEulerState(const Eigen::VectorXd& x, double lambda) const;
  /// True when equations r meet every tolerance of the options and conditions.
  bool meetsTolerances(const Eigen::VectorXd& r) const;
  const Eigen::VectorXd& getUnknownScales() const { return xScale_; }    ///< typical sizes of the unknowns
  const Eigen::VectorXd& getEquationScales() const { return rScale_; }   ///< equation weights (to newtons)

 private:
  void applyDrive(double lambda) const;
  void fillResult(const Eigen::VectorXd& x, const Eigen::VectorXd& r, SteadyStateResult& res) const;
  void setUnknowns(const Eigen::VectorXd& x) const;
  SteadyStateResult solveFrom(SimTK::State se, const SimTK::Vector& lambda0, const std::vector<double>& p0);
  void calcJacobian(const Eigen::VectorXd& x, const Eigen::VectorXd& r, Eigen::MatrixXd& J) const;
  std::string describeEquation(int row) const;

  const Scene& scene_;
  SteadyStateProblem problem_;
  SteadyStateOptions opt_;
  std::vector<int> qAll_;     // q indices in use (Euler state)
  std::vector<int> qe_, ue_;  // effective q and u (Euler state)
  std::vector<int> fu_, cu_;  // mobilities whose force equations are solved / checked (u indices)
  mutable Eigen::VectorXd checkedForces_;  // the checked force equations at the last calcEquations
  int nf_ = 0;                // solved force equations (= effective q + effective u)
  int nq_ = 0, nu_ = 0, nz_ = 0, mp_ = 0, mv_ = 0, m_ = 0, np_ = 0, n_ = 0;
  mutable std::vector<double> curP_;  // parameter values the model holds now
  mutable double lastEquilibriumResidual_ = 0;  // max |reduced rate| at the last linearisation point
  Eigen::VectorXd xScale_, rScale_;  // typical sizes of unknowns; equation weights
  mutable SimTK::State se_;           // workspace (Euler-angle form)
  mutable int evaluations_ = 0;
  Eigen::MatrixXd J_;
  bool haveJacobian_ = false;
  std::function<void(SimTK::State&, double)> drive_;  // driving condition of continueSteadyState
  double driveScale_ = 1;
  mutable double drivenLambda_ = std::numeric_limits<double>::quiet_NaN();  // lambda the workspace holds
};

/// One point of a continuation.
struct ContinuationPoint {
  double value = 0;           ///< the driving condition
  bool converged = false;
  std::string failure;        ///< the solver's message when not converged
  SteadyStateResult result;   ///< valid when converged
};

struct ContinuationOptions {
  /// A failed step is retried as up to this many halvings from the last
  /// converged point before the point is declared without a steady state.
  int max_bisections = 4;
  /// After a point fails, report the remaining values as beyond the branch's
  /// end instead of solving them from a distant start (which can land on
  /// another, unrelated branch).
  bool stop_at_branch_end = true;
  /// Optional branch check: called for every converged solve (intermediate
  /// points of a bisected step too) with the previous point of the branch
  /// (nullptr for the first) and the new one; a non-empty return refuses the
  /// solution as a jump to another branch (the step is then bisected like a
  /// failed solve, and the point reported without a steady state with the
  /// reason if no bisection stays on the branch).
  std::function<std::string(const SteadyStateResult* previous, double previousValue, const SteadyStateResult& next,
                            double value)>
      accept;
};

/// Follows the steady state as a driving condition takes `values` in turn:
/// `setCondition(state, value)` applies it (e.g. a speed, a steering angle);
/// each solve starts from the previous solutions extrapolated along the branch
/// (linear through two, quadratic through three converged points).
std::vector<ContinuationPoint> followSteadyState(SteadyStateSolver& solver, const SimTK::State& start,
                                                 const std::vector<double>& values,
                                                 const std::function<void(SimTK::State&, double)>& setCondition,
                                                 const ContinuationOptions& options = {});

/// Steady-state sensitivity (4.47)-(4.49): d outputs / d p by central
/// differences of converged solutions at p0 +- h. With no h given, h =
/// scale * cbrt(1e-10) (the solver's relative precision, ~1e-10, balanced against
/// the O(h^2) truncation), scale = max(|p0|, typical).
std::vector<double> calcSteadyStateSensitivity(
    SteadyStateSolver& solver, const SteadyStateResult& nominal, double p0, double typical,
    const std::function<void(SimTK::State&, double)>& setCondition,
    const std::function<std::vector<double>(const SimTK::State&)>& outputs, double h = 0);

/// Pseudo-arclength continuation (vdyn/steady_state/arclength.h) of a steady
/// state in a driving condition that `setCondition(state, value)` applies (a
/// held steering angle, a held speed), from the converged `start` at value0,
/// through folds; with `stability` each point carries the eigenvalues of
/// calcStability (Hopf test, stable/unstable labels). value_scale: the
/// condition's typical size (its unit), the arclength metric's lambda scale.
/// A point's steady state: solver.makeDrivenResult(point.x, point.lambda).
ArclengthResult continueSteadyState(SteadyStateSolver& solver, const SteadyStateResult& start, double value0,
                                    const std::function<void(SimTK::State&, double)>& setCondition,
                                    double value_scale, bool stability, const ArclengthOptions& options);

}  // namespace vdyn
