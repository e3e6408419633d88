#pragma once
// Dense forward dynamics for the reduced 4WS vehicle: its constraint rows (the
// eight arm rows of ArmPlanesImpl, one steering row per steered knuckle with a
// time command, the speed hold (3.18)) solved as one small dense KKT system
// instead of Simbody's per-row path (calcGMInvGt: one pass over every
// constraint object per row, 55 % of the instructions with the rows in
// Simbody, issue 13).
//
// The rows, written on the reduced coordinates (q_L, q_U the lower and upper
// arm Pin angles, s and delta the knuckle's mobilities):
//   lower arm   q_L - s = 0              (the lower arm's angle is s)
//   upper arm   q_U - theta4(s) = 0      (WishboneLoop::calcUpperArmAngle)
//   steering    delta - delta_cmd(t) = 0 (the knuckle's delta is the angle of
//               (A.1) by construction, so this is the steering constraint)
//   state-driven steering  delta - q_D = 0 (q_D the steer body's angle, whose
//               Motion prescribes q_D'' = the SteeringLaw's delta'': the
//               SteeringStateConstraintImpl row x_B . (s_F - y_D) = 0 written
//               on the reduced coordinates, -sin(delta) = -sin(q_D))
//   speed hold  (v_xi^2 + v_eta^2 - U0^2) / (2 U0) = 0 (SpeedHoldImpl's row)
//   steering law  u_D' = x_D per state-driven steering (Law): the steer
//               body's Motion is disabled in a dense state and its delta''
//               is this row's right side, solved with the rest (below)
// They are the same constraints as the Simbody rows (a point in the arm's
// plane through its pivot axis holds exactly when the arm's angle is the
// loop's), so the equations of motion are the same. Per evaluation, with the
// applied forces f (every force element's, summed by Simbody) and M, G, b:
//   udot0 = M^-1 (f - c)                (calcAccelerationIgnoringConstraints)
//   A     = G M^-1 G^T                  (from the articulated-body inertias:
//                                        formBlocks in reduced_dense.cpp)
//   A lambda = b - G udot0              (dense Cholesky, m <= 13)
// and G^T lambda is added to the mobility forces, so Simbody's own tree
// solve returns udot = udot0 + M^-1 G^T lambda, which meets G udot = b.
// A needs no tree pass of its own: every row touches only the chassis (a
// child of Ground) and its children, where M^-1 is given by the chassis's
// articulated inertia and each child's (H^T P H) and coupling; rows on other
// bodies would take one multiplyByMInv per row (calcRowMatrix compares both).
// A prescribed mobility (the steer body's) is not free: udot0 carries its
// prescribed u' (calcAccelerationIgnoringConstraints obeys Motions) and
// M^-1 is 0 there (multiplyByMInv's convention; formBlocks leaves it out),
// so its column of G enters G udot0 only and
// its share of G^T lambda is carried by the Motion's reaction, as the
// Simbody row's is.
//
// The steering laws. A law's delta'' may read the chassis's acceleration
// (the path controller's x'' of (7.13), SteeringLaw::readsStationAcceleration)
// or another steering's delta'' (the rear-steer law reads the front's), and
// the accelerations depend on every delta'' in turn: one algebraic loop,
// solved in each evaluation. The system is linear in the right sides x of the
// law rows, lambda(x) = A^-1 (r0 + E x), so the chassis's acceleration is
// affine in x, a(x) = a0 + C x (from the chassis's share of M^-1 G^T, the
// blocks' S^-1 w_i); each law is evaluated at the current x (the others'
// delta'' read through SteeringPlugin::ExternalSolve, the station's
// acceleration given), sweep after sweep (Gauss-Seidel) until a sweep moves
// no x by more than 1e-10 (1 + |x|) rad/s^2. The sweeps are accelerated
// (Anderson): each starts from the combination of the last sweeps' outputs
// whose combined residual is least, so for laws affine in x'' and in the
// others' delta'' (the path and rear-steer laws) sweep nL + 2 starts at the
// fixed point to rounding and confirms it (ch8's fifteen runs: 3.2 sweeps
// per evaluation, mostly three, where plain sweeps took 2-9, 5.6 on average;
// the coupling is the steering's own inertia). delta'' and x'' then satisfy
// the law and the equations of motion together, with no lag state.
//
// Simbody does not know these rows, so it does not project onto them; their
// drift is held by Baumgarte terms (b - 2 w verr - w^2 perr for the holonomic
// rows, b - w verr for the speed hold, w = kBaumgarteRate_per_s), which vanish
// on the constraint manifold. The drift stays at the integrator's error
// level (ch3_work_precision reports it).
//
// Active only in a state where WheeledVehicle::useDenseRows() set its flag
// (and disabled the Simbody constraints it replaces); in every other state
// this force does nothing and the Simbody rows act. Simbody's constraint
// multipliers are not available in a dense state; the speed hold's force
// (speed_hold.force_N) is read from this element (speedHoldForce).
#include <memory>
#include <vector>

#include <Simbody.h>

#include "vdyn/steering/steering.h"
#include "vdyn/vehicles/reduced_wishbone.h"

namespace vdyn {

class SpeedHoldPlugin;

class ReducedDenseRows : public SimTK::Force::Custom::Implementation {
 public:
  static constexpr double kBaumgarteRate_per_s = 50.0;

  ReducedDenseRows(const SimTK::SimbodyMatterSubsystem& matter, const SimTK::GeneralForceSubsystem& forces)
      : matter_(&matter), forces_(&forces) {}

  /// The rows (set by WheeledVehicle::useDenseRows before the first dense state).
  struct Arm {
    SimTK::MobilizedBody::Pin lower, upper;
    SimTK::MobilizedBody::Custom knuckle;
    /// The knuckle's implementation (owned by the matter subsystem): the
    /// upper arm's row reads theta4(s) from the kinematics its State holds.
    const ReducedKnuckleMobilizer* mobilizer = nullptr;
  };
  /// A steered knuckle: time-commanded (`command`), or state-driven (no
  /// command; `steer` the steering plugin's steer body, whose Motion
  /// prescribes u' = delta'' from the controller's SteeringLaw).
  struct Steer {
    SimTK::MobilizedBody::Custom knuckle;
    std::shared_ptr<const SteeringCommand> command;
    SimTK::MobilizedBody steer;
  };
  struct Speed {
    SimTK::MobilizedBody::Free chassis;
    const SpeedHoldPlugin* plugin = nullptr;
  };
  /// A state-driven steering whose delta'' the rows solve (its steer body's
  /// Motion disabled in a dense state).
  struct Law {
    const SteeringPlugin* plugin = nullptr;
  };
  void setRows(std::vector<Arm> arms, std::vector<Steer> steers, std::vector<Speed> speeds, std::vector<Law> laws);
  /// Every row, the steering laws' included.
  int numRows() const { return int(arms_.size() * 2 + steers_.size() + speeds_.size() + laws_.size()); }
  /// The rows that stand for Simbody constraints (all but the laws').
  int numConstraintRows() const { return int(arms_.size() * 2 + steers_.size() + speeds_.size()); }
  /// The k-th law's delta'' (rad/s^2) in a dense state realized to
  /// Stage::Dynamics (during the solve: its current value).
  double solvedSteerAcceleration(const SimTK::State& s, int k) const;
  /// Sweeps of the last solve of the laws in `s` (Stage::Dynamics; tests).
  int lastLawSweeps(const SimTK::State& s) const;

  bool isActive(const SimTK::State& s) const;
  void setActive(SimTK::State& s, bool active) const;

  /// Largest position error of the holonomic rows (rad) and velocity error of
  /// every row (rad/s; m/s for the speed hold) in `s` (Stage::Velocity).
  std::pair<double, double> calcRowErrors(const SimTK::State& s) const;
  /// Force of the k-th speed hold along the direction of travel, N
  /// (SpeedHoldPlugin::calcForce's sign), in a dense state (Stage::Dynamics);
  /// 0 when it is released.
  double speedHoldForce(const SimTK::State& s, int k) const;
  /// Releases (false) or engages (true) the k-th speed hold's row in a dense
  /// state (SpeedHoldPlugin::setEnabled; invalidates Stage::Instance).
  void setSpeedHoldEnabled(SimTK::State& s, int k, bool enabled) const;
  bool isSpeedHoldEnabled(const SimTK::State& s, int k) const;

  // Force::Custom::Implementation
  void calcForce(const SimTK::State&, SimTK::Vector_<SimTK::SpatialVec>&, SimTK::Vector_<SimTK::Vec3>&,
                 SimTK::Vector&) const override {}
  SimTK::Real calcPotentialEnergy(const SimTK::State&) const override { return 0; }
  bool dependsOnlyOnPositions() const override { return false; }
  void realizeTopology(SimTK::State& s) const override;
  /// Runs after every force element's calcForce (GeneralForceSubsystem calls
  /// realizeDynamics of its forces once the sums are complete): adds G^T lambda.
  void realizeDynamics(const SimTK::State& s) const override;

 /// G M^-1 G^T of the rows in `s` (Stage::Dynamics of a dense state), by
  /// the articulated-body blocks (`byProducts` false, what realizeDynamics
  /// uses when the rows' bodies allow it) or by one multiplyByMInv per row
  /// (true): two independent ways, for tests.
  SimTK::Matrix calcRowMatrix(const SimTK::State& s, bool byProducts) const;

 private:
  /// One row: sparse G (u index, coefficient, mobilized body, its mobility),
  /// the right side b of G udot = b (with the Baumgarte terms), and the errors.
  struct RowEval {
    int n = 0;
    int u[3];
    double g[3];
    int body[3];  ///< MobilizedBodyIndex of u[k]
    int ux[3];    ///< u[k]'s index among its mobilizer's mobilities
    double b = 0, perr = 0, verr = 0;
  };
  /// Which bodies the rows touch (Stage::Instance: the speed holds released
  /// change the rows), computed on the first evaluation after a change.
  struct Structure {
    /// Every row touches only the chassis (a child of Ground, u' free) and
    /// its children: formBlocks applies.
    bool blocks = false;
    const SimTK::MobilizedBody* chassis = nullptr;
    int nc = 0;  ///< the chassis's mobilities
    struct Child {
      const SimTK::MobilizedBody* body;
      int nu;
      bool known;  ///< prescribed u': M^-1 is 0 on its mobilities
    };
    std::vector<Child> children;
    std::vector<int> entryChild;  ///< per row entry (3 per row): index into children, -1 the chassis
    /// Entries (row i, entry k) and (row j, entry l), i >= j, on the same
    /// free child: the terms of g_ib^T D^-1 g_jb.
    struct Pair {
      int i, k, j, l, child;
    };
    std::vector<Pair> pairs;
  };
  /// A child's D^-1 = (H^T P H)^-1 (H its hinge matrix in Ground at its
  /// origin, P its articulated-body inertia) and L = H_c^T Phi P H D^-1 (the
  /// chassis's share, H_c the chassis's hinge matrix, Phi the shift to its
  /// origin).
  struct ChildBlocks {
    double Dinv[6][6];
    double L[6][6];  ///< L[c][j]: chassis mobility c, the child's mobility j
  };
  /// Per-state workspace (a cache entry; no buffers shared between states).
  struct Work {
    std::vector<RowEval> rows;
    SimTK::Vector udot0, v;
    std::vector<SimTK::Vector> Y;
    SimTK::Vector_<SimTK::SpatialVec> A_GB;
    std::vector<double> A, r, t;
    std::vector<ChildBlocks> blocks;
    double S[36];  ///< the chassis's articulated inertia's factor (formBlocks)
    bool haveS = false;
    // The laws' solve: x their delta'', solving while it runs.
    std::vector<double> x, lam0, Lam, Z;
    // Its acceleration (solveLaws): a sweep's start and residual, the last
    // one's output and residual, and the differences kept (column-major, nL each).
    std::vector<double> start, f, gPrev, fPrev, dG, dF;
    bool solving = false;
  };
  /// The laws' solve and the multipliers, given A factored and w.r = r0.
  void solveLaws(const SimTK::State& s, Work& w) const;
  void evalRows(const SimTK::State& s, std::vector<RowEval>& rows) const;
  Work& updWork(const SimTK::State& s) const;
  const Structure& getStructure(const SimTK::State& s, const std::vector<RowEval>& rows) const;
  /// Fills w.A (lower triangle, m x m) with G M^-1 G^T; false if the rows'
  /// bodies are not the chassis (a Ground child) and its children (then
  /// the products are used, or when `byProducts`).
  bool formBlocks(const SimTK::State& s, Work& w) const;
  void formProducts(const SimTK::State& s, Work& w) const;

  const SimTK::SimbodyMatterSubsystem* matter_;
  const SimTK::GeneralForceSubsystem* forces_;
  std::vector<Arm> arms_;
  std::vector<Steer> steers_;
  std::vector<Speed> speeds_;
  std::vector<Law> laws_;
  mutable SimTK::DiscreteVariableIndex activeIndex_;
  mutable SimTK::DiscreteVariableIndex releasedIndex_;  ///< std::vector<int>: 1 = the k-th hold released
  mutable SimTK::CacheEntryIndex lambdaIndex_;  ///< the multipliers (Stage::Dynamics)
  mutable SimTK::CacheEntryIndex solvedIndex_;  ///< the laws' delta'' and the sweeps (Stage::Dynamics)
  mutable SimTK::CacheEntryIndex workIndex_;    ///< Work (Stage::Instance: its contents are scratch)
  mutable SimTK::CacheEntryIndex structureIndex_;  ///< Structure (Stage::Instance, lazy)
};

}  // namespace vdyn
