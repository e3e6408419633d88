#pragma once
// The reduced double-wishbone corner: the App. A loop (lower arm, knuckle,
// upper arm, chassis) closed inside the tree instead of by a Constraint::Ball.
//
// The knuckle sits on a two-mobility custom mobilizer on the chassis whose
// coordinates are the corner's suspension coordinate s (the lower arm's pivot
// angle, rad, the angle of the constrained model's lower-arm Pin) and the
// steering angle delta of (A.1) (rad, + left: x_chassis . s_knuckle =
// -sin(delta)). Its transform solves the loop in closed form:
//   L(s)      lower ball centre, on the lower arm turned by s about joint 1;
//   theta4(s) upper arm angle: the upper ball on its circle about joint 4 at
//             the knuckle's ball-to-ball distance from L (circle-sphere
//             intersection, a cos + b sin = c);
//   kingpin   k = (U - L) / |U - L|; the knuckle's own kingpin vector is
//             carried onto k by the smallest rotation, then turned about k by
//             the angle phi(s, delta) at which the spin axis meets (A.1)
//             (again a cos + b sin = c).
// The position, its first and second derivatives in (s, delta) are evaluated
// together in second-order forward-mode jets, so H and HDot are exact (the
// tests check them, and the arm coupling, by finite differences).
//
// The arms keep their bodies, masses and inertias on their own Pins (the
// constrained model's joints 1 and 4). Their angles are tied to s by one
// holonomic row each: the knuckle's ball point (on the arm's circle by
// construction) lies in the plane of the arm through its pivot axis and its
// ball point (the equations of Constraint::PointInPlane, body-level, all
// corners' rows in one constraint object; coordinate rows cost Simbody a
// q-to-u force conversion per mobilizer and were slower). No row
// closes the loop itself, so the loop closure and the steering angle are
// exact by construction. A Simbody tree cannot do without these two rows:
// every body whose pose depends on s needs a mobilizer of its own, and only
// one body of a chain can depend on s alone.
#include <string>
#include <vector>

#include <Simbody.h>

#include "vdyn/core/scene.h"
#include "vdyn/vehicles/double_wishbone.h"

namespace vdyn {

/// Second-order forward-mode jet in two variables (s, delta): value, gradient
/// and Hessian (d00, d01, d11).
struct Jet2 {
  double v = 0, d[2] = {0, 0}, h[3] = {0, 0, 0};
  Jet2() = default;
  Jet2(double value) : v(value) {}  // NOLINT: constants promote implicitly
  static Jet2 variable(double value, int which) {
    Jet2 j(value);
    j.d[which] = 1;
    return j;
  }
  /// Second derivative d2/(dq_i dq_k).
  double second(int i, int k) const { return h[i + k]; }
};

/// The closed-form loop of one corner (chassis frame C; the knuckle frame K).
class WishboneLoop {
 public:
  explicit WishboneLoop(const DoubleWishboneParams& p);

  /// Knuckle pose and its derivatives in (s, delta).
  struct Pose {
    Jet2 R[3][3];   ///< R_CK
    Jet2 p[3];      ///< knuckle origin in C, m
    Jet2 theta4;    ///< upper arm angle (depends on s only), rad
  };
  /// Throws Error if the loop cannot close at s (the upper ball out of reach)
  /// or the steering angle is out of the knuckle's reach.
  Pose calcPose(double s_rad, double delta_rad) const;
  /// The knuckle transform alone (plain doubles).
  SimTK::Transform calcTransform(double s_rad, double delta_rad) const;

  /// Upper arm angle theta4(s) and its first two derivatives, rad.
  SimTK::Vec3 calcUpperArmAngle(double s_rad) const;

 private:
  Pose solve(const Jet2& s, const Jet2& delta, bool upperOnly) const;
  // Lower arm: L = P1 + R1 Rz(s) m1; upper arm: U = P4 + R4 Rz(theta4) m4.
  SimTK::Vec3 P1_, m1_, P4_, m4_;
  SimTK::Mat33 R1_, R4_;
  SimTK::Vec3 lK_, kK_, spinK_;  // knuckle: lower ball, unit kingpin, spin axis (K frame)
  double d_ = 0;                 // ball-to-ball distance of the knuckle, m
  double sign4_ = 1, signPhi_ = 1, offset4_ = 0, offsetPhi_ = 0;  // branches chosen at s = delta = 0
};

/// The knuckle's two-mobility custom mobilizer, q = u-integral = [s, delta].
/// The pose and H, dH/dq at the last q are kept in a cache entry of the State
/// (Simbody asks for X_FM, H, H^T, HDot and HDot^T at the same q many times
/// per evaluation); the mobilizer itself holds nothing that changes.
class ReducedKnuckleMobilizer : public SimTK::MobilizedBody::Custom::Implementation {
 public:
  ReducedKnuckleMobilizer(SimTK::SimbodyMatterSubsystem& matter, const WishboneLoop& loop);
  Implementation* clone() const override { return new ReducedKnuckleMobilizer(*this); }
  void setMobilizedBody(SimTK::MobilizedBodyIndex mbx) { mbx_ = mbx; }

  SimTK::Transform calcMobilizerTransformFromQ(const SimTK::State& s, int nq, const SimTK::Real* q) const override;
  SimTK::SpatialVec multiplyByHMatrix(const SimTK::State& s, int nu, const SimTK::Real* u) const override;
  void multiplyByHTranspose(const SimTK::State& s, const SimTK::SpatialVec& F, int nu, SimTK::Real* f) const override;
  SimTK::SpatialVec multiplyByHDotMatrix(const SimTK::State& s, int nu, const SimTK::Real* u) const override;
  void multiplyByHDotTranspose(const SimTK::State& s, const SimTK::SpatialVec& F, int nu, SimTK::Real* f) const override;

  /// Columns of H (V_FM = H u) and the derivatives dH_j/dq_k at q (public for tests).
  struct Kinematics {
    double q0 = NAN, q1 = NAN;
    SimTK::Transform X;
    SimTK::SpatialVec H[2];
    SimTK::SpatialVec dH[2][2];  ///< dH[j][k] = d(H column j) / d q_k
    SimTK::Vec3 theta4;          ///< the upper arm angle theta4(s), d/ds, d2/ds2 (rad, rad, rad)
  };
  Kinematics calcKinematics(double q0, double q1) const;
  /// theta4(s) and its first two derivatives at the state's s, from the
  /// kinematics the State holds (the ones its Stage::Position used).
  SimTK::Vec3 getUpperArmAngle(const SimTK::State& s) const { return atState(s).theta4; }

  /// Allocates the kinematics cache entry (Simbody calls it).
  void realizeTopology(SimTK::State& s) const override;

 private:
  /// The kinematics at (q0, q1) from the State's cache entry, computed there
  /// when it holds another q.
  const Kinematics& getKinematics(const SimTK::State& s, double q0, double q1) const;
  const Kinematics& atState(const SimTK::State& s) const;
  WishboneLoop loop_;
  const SimTK::SimbodyMatterSubsystem* matter_;
  SimTK::MobilizedBodyIndex mbx_;
  mutable SimTK::CacheEntryIndex kinematicsIndex_;  ///< Kinematics (Stage::Model; keyed by its q)
};

/// The arm rows of every reduced corner of a vehicle in one Constraint::Custom
/// (one row per arm): each knuckle ball point S lies in its arm's plane
/// through the pivot axis and the arm's ball point, the equations of
/// Simbody's Constraint::PointInPlane (perr = p_BS . n - h, verr = v_CS . n,
/// aerr = (a_CS - 2 w_B x v_CS) . n, force lambda n on S and -lambda n on the
/// arm's coincident point C). One constraint object instead of eight: Simbody
/// visits every constraint object for every row of G M^-1 G^T.
class ArmPlanesImpl : public SimTK::Constraint::Custom::Implementation {
 public:
  struct Row {
    SimTK::MobilizedBody arm, knuckle;
    SimTK::UnitVec3 normal_arm;  ///< plane normal in the arm frame
    double height_m = 0;         ///< plane: normal . p = height (arm frame)
    SimTK::Vec3 point_knuckle;   ///< the knuckle's ball point (knuckle frame)
  };
  ArmPlanesImpl(SimTK::SimbodyMatterSubsystem& matter, const std::vector<Row>& rows);
  Implementation* clone() const override { return new ArmPlanesImpl(*this); }
  void calcPositionErrors(const SimTK::State& s, const SimTK::Array_<SimTK::Transform, SimTK::ConstrainedBodyIndex>& X_AB,
                          const SimTK::Array_<SimTK::Real, SimTK::ConstrainedQIndex>&,
                          SimTK::Array_<SimTK::Real>& perr) const override;
  void calcPositionDotErrors(const SimTK::State& s, const SimTK::Array_<SimTK::SpatialVec, SimTK::ConstrainedBodyIndex>& V_AB,
                             const SimTK::Array_<SimTK::Real, SimTK::ConstrainedQIndex>&,
                             SimTK::Array_<SimTK::Real>& pverr) const override;
  void calcPositionDotDotErrors(const SimTK::State& s,
                                const SimTK::Array_<SimTK::SpatialVec, SimTK::ConstrainedBodyIndex>& A_AB,
                                const SimTK::Array_<SimTK::Real, SimTK::ConstrainedQIndex>&,
                                SimTK::Array_<SimTK::Real>& paerr) const override;
  void addInPositionConstraintForces(const SimTK::State& s, const SimTK::Array_<SimTK::Real>& multipliers,
                                     SimTK::Array_<SimTK::SpatialVec, SimTK::ConstrainedBodyIndex>& bodyForcesInA,
                                     SimTK::Array_<SimTK::Real, SimTK::ConstrainedQIndex>&) const override;

 private:
  struct R {
    SimTK::ConstrainedBodyIndex B, F;  // arm (plane), knuckle (follower)
    SimTK::UnitVec3 n;
    double h;
    SimTK::Vec3 p;
  };
  std::vector<R> rows_;
  /// Position-stage quantities of every row (n_A and the station offsets of S
  /// from the knuckle's and the arm's origins, in A), kept in a cache entry of
  /// the State with the q they were computed at: Simbody multiplies by G and
  /// G^T once per row of G M^-1 G^T at the same positions.
  struct Geo {
    SimTK::Vec3 n, rF, rB;
  };
  struct GeoCache {
    SimTK::Vector q;
    std::vector<Geo> rows;
  };
  const std::vector<Geo>& geometry(const SimTK::State& s) const;

 public:
  /// Allocates the geometry cache entry (Simbody calls it).
  void realizeTopology(SimTK::State& s) const override;

 private:
  mutable SimTK::CacheEntryIndex geoIndex_;  ///< GeoCache (Stage::Model; keyed by its q)
};

/// The two rows (lower, upper arm) of a reduced corner for ArmPlanesImpl.
std::vector<ArmPlanesImpl::Row> armPlaneRows(const DoubleWishboneParams& p, const SimTK::MobilizedBody& lowerArm,
                                             const SimTK::MobilizedBody& knuckle,
                                             const SimTK::MobilizedBody& upperArm);

/// Handles of a reduced corner built into a scene.
struct ReducedWishboneCorner {
  SimTK::MobilizedBody::Pin lower_arm;   ///< its angle tied to s
  SimTK::MobilizedBody::Custom knuckle;  ///< q = [s, delta]
  const ReducedKnuckleMobilizer* knuckle_mobilizer = nullptr;  ///< its implementation (owned by the matter subsystem)
  SimTK::MobilizedBody::Pin upper_arm;   ///< its angle tied to theta4(s)
  SimTK::MobilizedBody::Pin wheel;
  SimTK::Force::TwoPointLinearSpring spring;
  SimTK::Force::TwoPointLinearDamper damper;
  const WishboneLoop* loop = nullptr;  ///< owned by the caller (WheeledVehicle)
};

/// The reduced corner (bodies registered as in buildDoubleWishbone). Its two
/// arm rows are not added here: collect armPlaneRows() of every corner into
/// one ArmPlanesImpl (WheeledVehicle does).
ReducedWishboneCorner buildReducedWishbone(Scene& scene, SimTK::MobilizedBody& chassis, const DoubleWishboneParams& p,
                                           const WishboneLoop& loop, const std::string& prefix);

/// Sets s, delta and the arm angles of a reduced corner (rates zero).
void setReducedCornerPosition(SimTK::State& s, const ReducedWishboneCorner& c, double s_rad, double delta_rad);

}  // namespace vdyn
