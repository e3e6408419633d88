#pragma once
// The suspension template "solid_axle": a dependent (rigid, beam) axle. One
// rigid housing carries both wheel centres; it moves on a free (6-dof)
// mobilizer relative to the chassis and is located by exactly four
// ball-ended links of fixed length (Constraint::Rod: chassis point - axle
// point), e.g. two lower trailing links, an upper torque link and a Panhard
// rod, or a triangulated four-link. 6 - 4 = 2 degrees of freedom per axle
// besides the wheel spins: the two wheel travels (heave and roll of the axle).
//
// Data: every point in the chassis frame at design (x forward, y left, z up),
// m; both sides given (a Panhard rod is not symmetric, so nothing is
// mirrored): the wheel centres spindle_right (y < 0) and spindle_left
// (y > 0), the four links, and a spring-damper per side between a chassis
// point and an axle point (one stiffness, damping and free length for both).
// Static camber (+ top of the wheel outward) and toe (+ toe-in) of the spin
// axes, fixed in the housing, the same on both sides.
//
// Bodies (roles "axle", "knuckle", "wheel"):
//   axle     the housing, its frame at its c.m. (bodies.axle.com_m), axes
//            parallel to the chassis at design. ONE body shared by both
//            sides: it is registered in the scene under both corners' names
//            (<right prefix>axle and <left prefix>axle name the same
//            MobilizedBody; Scene maps names to bodies, so a body may have
//            two names), so getBody(0, "axle") and getBody(1, "axle") are the
//            same body. calcCornerMass counts half of it on each side.
//   knuckle  per side: the hub carrier (bearing, brake) on a Weld to the
//            housing at the wheel centre, its c.m. there: the body carrying
//            the wheel's spin joint, as on every template (the tire and the
//            plugins reach the wheel through it). It does not steer:
//            isSteerable() is false (a rear axle; the axle offers no knuckles
//            to a steering plugin).
//   wheel    per side, on its spin pin about the spin axis at the wheel centre.
// Build order: the right corner adds the housing, its four links, the right
// knuckle, wheel and spring-damper; the left corner its knuckle, wheel and
// spring-damper.
#include <string>
#include <vector>

#include "vdyn/core/fields.h"
#include "vdyn/vehicles/double_wishbone.h"
#include "vdyn/vehicles/suspension.h"

namespace vdyn {

/// A ball-ended link of fixed length between the chassis and the axle housing.
struct SolidAxleLink {
  std::string name;          ///< for messages and outputs ("panhard_rod")
  SimTK::Vec3 chassis_m{0, 0, 0};  ///< chassis point, chassis frame, m
  SimTK::Vec3 axle_m{0, 0, 0};     ///< axle point at design, chassis frame, m (its length is the design distance)
  double length() const { return (axle_m - chassis_m).norm(); }
};

struct SolidAxleParams {
  RigidBodyParams axle;                 ///< the housing: mass, inertia about its c.m. (chassis axes)
  SimTK::Vec3 axle_com_m{0, 0, 0};      ///< the housing's c.m., chassis frame at design, m
  RigidBodyParams knuckle;              ///< each side's hub carrier, its c.m. at the wheel centre
  RigidBodyParams wheel;                ///< each side's spindle, hub, rim and tire, at the wheel centre
  SimTK::Vec3 spindle_m[2] = {SimTK::Vec3(0), SimTK::Vec3(0)};           ///< wheel centres, right (y < 0) then left (y > 0), chassis frame, m
  std::vector<SolidAxleLink> links;     ///< exactly four
  SimTK::Vec3 spring_chassis_m[2] = {SimTK::Vec3(0), SimTK::Vec3(0)};    ///< spring-damper chassis point, right then left, m
  SimTK::Vec3 spring_axle_m[2] = {SimTK::Vec3(0), SimTK::Vec3(0)};       ///< spring-damper axle point at design, right then left, m
  double camber_rad = 0;                ///< static camber of both wheels, + top outward
  double toe_in_rad = 0;                ///< static toe of both wheels, + toe-in
  double spring_stiffness_N_per_m = 0;  ///< each side's spring, along its line
  double damper_N_s_per_m = 0;
  double spring_free_length_m = 0;
  SpringStopParams stops;  ///< bump and rebound stops along each side's spring line (none by default)

  /// Throws Error naming `where` and the key: link count, a link of zero
  /// length, duplicate or empty link names, a wheel centre on the wrong side,
  /// coincident spring points, a linkage that with the two wheel heights does
  /// not fix the housing's pose (singular at design), body and spring values.
  void validate(const std::string& where) const;
  static const FieldTable<SolidAxleParams>& fields();
  /// The wheel's spin axis at design, chassis frame, pointing to the vehicle's
  /// left (+y) on either side, from camber and toe; `right` picks the side.
  SimTK::UnitVec3 calcSpinAxis(bool right) const;
  /// Smallest singular value of the design linkage's 6 x 6 Jacobian (the four
  /// link lengths and the two wheel-centre heights against the housing's
  /// small rotation, scaled by the half track, and translation), over its
  /// largest: 0 when the links and wheel travels leave a motion of the housing
  /// free (e.g. four parallel links), 1 at best.
  double calcLinkageConditioning() const;
};

/// Handles of one built side.
struct SolidAxleCorner {
  SimTK::MobilizedBody::Weld knuckle;
  SimTK::MobilizedBody::Pin wheel;
  SimTK::Force::TwoPointLinearSpring spring;
  SimTK::Force::TwoPointLinearDamper damper;
};

class SolidAxleSuspension : public Suspension {
 public:
  explicit SolidAxleSuspension(const SolidAxleParams& p);
  const SolidAxleParams& getParams() const { return p_; }
  /// After build(): the housing (on its free mobilizer), the links (in data
  /// order) and a side's knuckle, wheel and spring-damper.
  const SimTK::MobilizedBody::Free& getHousing() const { return housing_; }
  const SimTK::Constraint::Rod& getLink(int i) const { return links_.at(i); }
  const SolidAxleCorner& getCorner(int side) const { return corners_[side]; }

  std::vector<std::string> bodyRoles() const override { return {"axle", "knuckle", "wheel"}; }
  /// Half the housing plus the side's knuckle and wheel, kg.
  double calcCornerMass(int side) const override;
  SimTK::Vec3 calcWheelCentreInChassis(int side) const override { return p_.spindle_m[side]; }
  SimTK::UnitVec3 getSpinAxis(int side) const override { return p_.calcSpinAxis(side == 0); }
  /// The wheel centre's travel from design, m, + up along the chassis z axis
  /// (needs s realized to Stage::Position).
  double getSuspensionCoordinate(const SimTK::State& s, int side) const override;
  /// Largest |link length - design length| in s, m (both sides: the links
  /// belong to the whole axle). Needs Stage::Position.
  double calcLoopGap(const SimTK::State& s, int side) const override;
  bool isSteerable() const override { return false; }
  // getKinematicCorner stays false: KinematicCorner drives a corner by one
  // coordinate of one travel body (a lower arm's pin angle) with the other
  // side locked, while a solid axle's wheel travel is a combination of the
  // housing's six free-mobilizer coordinates and moves the other wheel too;
  // its kinematics are the housing's pose at given right and left travels
  // (tests/test_solid_axle.cpp sweeps them).

 protected:
  void DoBuildCorner(Scene& scene, SimTK::MobilizedBody& chassis, int side, const std::string& prefix) override;
  void DoShiftChassisFrame(const SimTK::Vec3& offset_m) override;

 private:
  SolidAxleParams p_;
  SimTK::MobilizedBody chassis_;
  SimTK::MobilizedBody::Free housing_;
  std::vector<SimTK::Constraint::Rod> links_;
  SolidAxleCorner corners_[2];
};

/// Registers "solid_axle" (registerSuspensionTemplates calls it).
void registerSolidAxle(PluginRegistry& registry);

}  // namespace vdyn
