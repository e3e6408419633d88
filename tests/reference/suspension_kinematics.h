#pragma once
// An independent suspension kinematics reference (test-only).
//
// Closes each suspension's loops by Newton's method on hardpoint distance and
// geometry equations with an analytic Jacobian, written apart from vdyn's
// multibody models (no vdyn or Simbody code): templates are tested against it.
//
// Frame and units: every point is in the chassis frame C (x forward, y left,
// z up; any origin, the caller's), in metres; angles in radians.
//
// Kinematic structures (Chrono::Vehicle's hardpoint names, as facts):
//   MacPherson strut: lower control arm (LCA) on a revolute chassis axis
//     through LCA_F and LCA_B, ball joint LCA_U to the upright; the strut is a
//     sliding joint: the upright carries the strut's lower point STRUT_U and
//     the strut axis (the design direction STRUT_U -> STRUT_C, fixed in the
//     upright), and that axis always passes through the chassis top mount
//     STRUT_C (universal/cylindrical top: the upright may slide along and turn
//     about it); tie rod of fixed length between TIEROD_C (on the chassis or the
//     rack) and TIEROD_U (upright). Chrono's SPRING_C/SHOCK_C is STRUT_C and
//     SPRING_U/SHOCK_U is STRUT_U (they coincide in its strut).
//   Double wishbone: upper and lower arms on revolute chassis axes
//     (UCA_F-UCA_B, LCA_F-LCA_B), ball joints UCA_U, LCA_U to the upright, tie
//     rod TIEROD_C-TIEROD_U of fixed length.
//   Solid axle: one rigid axle body carrying both wheel centres, located by
//     exactly four ball-ended links of fixed length (chassis point - axle
//     point), e.g. two lower trailing links, an upper (torque) link and a
//     Panhard rod, or a triangulated four-link. Two degrees of freedom: the
//     two wheel travels.
//   Rack and pinion: the rack moves both inner tie-rod points TIEROD_C by the
//     same lateral displacement (chassis +y); rack travel = c * pinion angle.
//
// Outputs (WheelKinematics), per wheel:
//   wheel travel z: the wheel centre's vertical displacement from its design
//     position, chassis z, + up (the driving input);
//   camber (ISO 8855 sense): positive when the top of the wheel leans outward
//     (away from the vehicle centre plane), for either side:
//     camber = asin(-s_out . z), s_out the unit spin axis pointing outward;
//   toe: toe-in positive (the front of the wheel turned toward the centre
//     plane), for either side: toe_in = atan2(s_out . x, s_out . y_out), y_out
//     the outward lateral unit vector (-y on the right, +y on the left);
//   steer angle delta (ISO 8855, vdyn's docs/conventions.md "Signs"): the
//     heading angle from chassis x, positive to the left (counter-clockwise
//     seen from above), delta = atan2(-s_left . x, s_left . y), s_left the spin
//     axis pointing left. Right wheel: delta = toe_in; left: delta = -toe_in;
//   track change: this wheel centre's lateral displacement, positive outward
//     (one side; a symmetric axle's track changes by twice this);
//   recession dx: the wheel centre's longitudinal displacement, chassis x,
//     + forward (a wheel moving rearward in bump has dx < 0).
//
// The side of a corner is the sign of its design wheel-centre y (y < 0: right).
// Errors (a singular loop, no convergence, bad input) throw std::runtime_error
// or std::invalid_argument with a message naming the cause.
#include <array>
#include <string>
#include <vector>

namespace vdyn::kinematics_reference {

using Vec3 = std::array<double, 3>;

/// Design spin axis, unit, pointing outward, from static camber and toe-in
/// (conventions above) for a corner whose outward side is sign(y_sign).
Vec3 spinAxisOutward(double camber_rad, double toe_in_rad, double y_sign);

/// MacPherson strut hardpoints of one corner at design, chassis frame, m.
struct MacPhersonHardpoints {
  Vec3 spindle;    ///< wheel centre (Chrono SPINDLE)
  Vec3 lca_f;      ///< lower arm front chassis pivot (LCA_F)
  Vec3 lca_b;      ///< lower arm rear chassis pivot (LCA_B)
  Vec3 lca_u;      ///< lower ball joint, arm - upright (LCA_U)
  Vec3 strut_c;    ///< strut top mount on the chassis (SPRING_C / SHOCK_C)
  Vec3 strut_u;    ///< strut lower point on the upright (SPRING_U / SHOCK_U)
  Vec3 tierod_c;   ///< inner tie-rod point, chassis or rack, at zero rack travel (TIEROD_C)
  Vec3 tierod_u;   ///< outer tie-rod point on the upright (TIEROD_U)
  double camber_rad = 0.0;  ///< static camber of the spin axis at design (sign above)
  double toe_in_rad = 0.0;  ///< static toe-in at design
};

/// Double-wishbone hardpoints of one corner at design, chassis frame, m.
struct DoubleWishboneHardpoints {
  Vec3 spindle;                 ///< wheel centre (SPINDLE)
  Vec3 uca_f, uca_b, uca_u;     ///< upper arm: front, rear chassis pivots; ball joint (UCA_*)
  Vec3 lca_f, lca_b, lca_u;     ///< lower arm: front, rear chassis pivots; ball joint (LCA_*)
  Vec3 tierod_c;                ///< inner tie-rod point at zero rack travel (TIEROD_C)
  Vec3 tierod_u;                ///< outer tie-rod point on the upright (TIEROD_U)
  double camber_rad = 0.0;
  double toe_in_rad = 0.0;
};

/// A ball-ended link of fixed (design) length between the chassis and the axle.
struct AxleLink {
  std::string name;  ///< for messages, e.g. "panhard_rod"
  Vec3 chassis;      ///< chassis point, m
  Vec3 axle;         ///< axle point at design, m
};

/// Solid axle at design, chassis frame, m. Both sides given (no mirroring:
/// a Panhard rod is not symmetric).
struct SolidAxleHardpoints {
  Vec3 spindle_right;            ///< right wheel centre (y < 0)
  Vec3 spindle_left;             ///< left wheel centre (y > 0)
  std::vector<AxleLink> links;   ///< exactly four links
  double camber_rad = 0.0;       ///< static camber of both spin axes (sign above)
  double toe_in_rad = 0.0;       ///< static toe-in of both wheels
};

/// Kinematics of one wheel at a solved pose.
struct WheelKinematics {
  Vec3 wheel_centre_m{};         ///< wheel centre, chassis frame
  Vec3 spin_axis_out{};          ///< unit spin axis, pointing outward
  double camber_rad = 0.0;       ///< + top of the wheel outward (absolute, includes static)
  double toe_in_rad = 0.0;       ///< + toe-in (absolute, includes static)
  double steer_rad = 0.0;        ///< ISO heading angle, + left
  double track_change_m = 0.0;   ///< wheel-centre lateral displacement, + outward
  double dx_m = 0.0;             ///< wheel-centre x displacement (recession), + forward
  double dz_m = 0.0;             ///< wheel-centre z displacement, + up (= the travel asked)
  double loop_residual = 0.0;    ///< largest |residual| of the closed loops at the solution, m
  int newton_iterations = 0;     ///< total over the continuation steps
  /// d(steer_rad)/d(rack travel) at this pose (implicit differentiation of the
  /// closed loops), rad/m; 0 for a solid axle.
  double dsteer_drack_rad_per_m = 0.0;
};

/// MacPherson corner at wheel travel z (m, + up) and rack travel (m, chassis
/// +y, moves tierod_c). Solved from the design pose by continuation.
WheelKinematics macphersonKinematics(const MacPhersonHardpoints& hp, double wheel_travel_m,
                                     double rack_travel_m = 0.0);

/// Double-wishbone corner at wheel travel z (m, + up) and rack travel (m, +y).
WheelKinematics doubleWishboneKinematics(const DoubleWishboneHardpoints& hp, double wheel_travel_m,
                                         double rack_travel_m = 0.0);

/// Double wishbone steered at the knuckle as vdyn's App. A corner is (its
/// (A.1), docs/equations.md "Steering"): no tie rod (tierod_* ignored); the
/// spin axis s_left (pointing left) is held at x . s_left = -sin(steer_rad).
/// Steps the steer angle by at most 0.01 rad from design.
/// dsteer_drack_rad_per_m is 0. steer_rad is the heading angle defined above
/// (atan2 of the spin axis' projection), which equals (A.1)'s angle only
/// while the spin axis stays in the chassis x-y plane (zero camber).
WheelKinematics doubleWishboneKinematicsKnuckleSteer(const DoubleWishboneHardpoints& hp, double wheel_travel_m,
                                                     double steer_rad);

struct AxleKinematics {
  WheelKinematics right, left;
  /// Axle roll: inclination of the wheel-centre line (right to left centre)
  /// from the chassis x-y plane, + when the left centre is higher (about +x).
  double roll_rad = 0.0;
};

/// Solid axle at right and left wheel travel (m, + up each).
AxleKinematics solidAxleKinematics(const SolidAxleHardpoints& hp, double travel_right_m,
                                   double travel_left_m);

/// Mirror images (y -> -y), for the other side of an independent axle.
MacPhersonHardpoints mirrored(const MacPhersonHardpoints& hp);
DoubleWishboneHardpoints mirrored(const DoubleWishboneHardpoints& hp);

/// Rack-and-pinion steering over a pair of corners mirrored from the right one.
struct RackSteer {
  double rack_travel_m = 0.0;   ///< c * pinion angle, chassis +y
  double steer_right_rad = 0.0; ///< ISO heading, + left
  double steer_left_rad = 0.0;
  double steer_mean_rad = 0.0;  ///< (left + right) / 2
  /// Overall steering ratio d(pinion angle)/d(mean road-wheel angle) =
  /// 1 / (c d(mean)/d(rack)), by implicit differentiation of the loops.
  double overall_ratio = 0.0;
  WheelKinematics right, left;
};

/// pinion_rad: steering-wheel (pinion) angle, + counter-clockwise seen by the
/// driver; c_m_per_rad: rack travel per pinion radian, signed (chassis +y per
/// +1 rad; with tie rods behind the axle a left turn moves the rack right, so
/// c < 0 gives a positive ratio); both wheels at wheel travel z (m, + up).
RackSteer rackSteer(const MacPhersonHardpoints& right, double pinion_rad, double c_m_per_rad,
                    double wheel_travel_m = 0.0);
RackSteer rackSteer(const DoubleWishboneHardpoints& right, double pinion_rad, double c_m_per_rad,
                    double wheel_travel_m = 0.0);

/// Largest |analytic - central finite difference| over the loop Jacobian's
/// entries at the solved pose for (travel, rack), step h (rotation increments
/// in rad, translations in m, arm angles in rad). Tests the analytic Jacobian.
double macphersonJacobianError(const MacPhersonHardpoints& hp, double wheel_travel_m,
                               double rack_travel_m, double h = 1e-6);
double doubleWishboneJacobianError(const DoubleWishboneHardpoints& hp, double wheel_travel_m,
                                   double rack_travel_m, double h = 1e-6);
double doubleWishboneKnuckleSteerJacobianError(const DoubleWishboneHardpoints& hp, double wheel_travel_m,
                                               double steer_rad, double h = 1e-6);
double solidAxleJacobianError(const SolidAxleHardpoints& hp, double travel_right_m,
                              double travel_left_m, double h = 1e-6);

}  // namespace vdyn::kinematics_reference
