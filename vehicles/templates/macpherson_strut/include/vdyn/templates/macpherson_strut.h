#pragma once
// The suspension template "macpherson_strut": a lower control arm on a
// revolute chassis joint, the upright (knuckle) on a ball joint at the arm's
// outer end, and the strut: a line fixed in the upright that always passes
// through the chassis top mount (a point-on-line constraint, 2 equations: the
// strut rod may slide in and turn about its own axis, as Chrono::Vehicle's
// MacPherson strut and Adams/Car's do with a cylindrical and a universal
// joint). The spring-damper acts between the top mount and the upright along
// the strut. The tie rod is optional: "tie_rod": "chassis" holds the upright's
// steer by a fixed-length rod from a chassis point (a rear axle, or a front
// axle checked for bump steer); "rack" puts the rod's inner end on the axle's
// steering rack (rack_and_pinion.h); "none" (default) leaves the upright free to
// turn about its kingpin (the line from the lower ball joint to the top mount)
// for a steering plugin, as the App. A double wishbone does.
//
// Data: hardpoints in the chassis frame at design (Chrono's names), bodies at
// their centres of mass (chassis frame, axes parallel to the chassis), the
// right corner; the left one is its mirror (eta -> -eta). Body roles:
// lower_arm, knuckle (the upright), wheel (spin joint at the spindle point).
// Degrees of freedom per corner: LCA pin 1 + ball 3 - strut 2 = 2 (travel and
// steer), 1 with the tie rod.
#include <memory>
#include <string>

#include "vdyn/core/fields.h"
#include "vdyn/vehicles/double_wishbone.h"
#include "vdyn/vehicles/suspension.h"

namespace vdyn {

/// A body of a hardpoint template: its mass properties and its centre of
/// mass in the chassis frame at design (the body frame's origin; its axes are
/// parallel to the chassis frame's there).
struct HardpointBody {
  RigidBodyParams body;
  SimTK::Vec3 com_m{0, 0, 0};
};

struct MacPhersonStrutParams {
  HardpointBody lower_arm, upright;
  RigidBodyParams wheel;                 ///< spindle, hub, rim and tire, at the spindle point
  // Hardpoints, chassis frame, m (Chrono: LCA_F, LCA_B, LCA_U, SPRING_C, SPRING_U, SPINDLE, TIEROD_C, TIEROD_U).
  SimTK::Vec3 lca_front_m, lca_back_m;   ///< the lower arm's chassis pivot axis
  SimTK::Vec3 lca_upright_m;             ///< lower ball joint
  SimTK::Vec3 strut_chassis_m;           ///< strut top mount
  SimTK::Vec3 strut_upright_m;           ///< strut's lower point on the upright (with the top mount: its axis)
  SimTK::Vec3 spindle_m;                 ///< wheel centre
  std::string tie_rod = "none";          ///< "none" | "chassis" | "rack" (inner end on the axle's rack)
  SimTK::Vec3 tierod_chassis_m, tierod_upright_m;  ///< tie rod ends (tie_rod "chassis" or "rack": inner at zero rack travel)
  double camber_rad = 0;                 ///< static camber, + top of the wheel outward
  double toe_in_rad = 0;                 ///< static toe, + toe-in
  double spring_stiffness_N_per_m = 0;   ///< along the strut, top mount to strut_upright
  double damper_N_s_per_m = 0;
  double spring_free_length_m = 0;
  SpringStopParams stops;                ///< bump and rebound stops along the strut (none by default)

  void validate(const std::string& where) const;
  static const FieldTable<MacPhersonStrutParams>& fields();
  /// The left corner: points mirrored eta -> -eta (camber and toe keep their sense).
  MacPhersonStrutParams mirrored() const;
  /// The wheel's spin axis at design, chassis frame, pointing to the vehicle's
  /// left (+eta) on either side, from camber and toe; `right` picks the side.
  SimTK::UnitVec3 calcSpinAxis(bool right) const;
};

/// Handles of a built corner.
struct MacPhersonStrutCorner {
  SimTK::MobilizedBody::Pin lower_arm;
  SimTK::MobilizedBody::Ball upright;
  SimTK::MobilizedBody::Pin wheel;
  SimTK::Constraint::PointOnLine strut;
  SimTK::Constraint::Rod tie_rod;  ///< empty handle without a tie rod
  SimTK::Force::TwoPointLinearSpring spring;
  SimTK::Force::TwoPointLinearDamper damper;
};

class MacPhersonStrutSuspension : public Suspension {
 public:
  explicit MacPhersonStrutSuspension(const MacPhersonStrutParams& right);
  const MacPhersonStrutParams& getCornerParams(int side) const { return params_[side]; }
  const MacPhersonStrutCorner& getCorner(int side) const { return corners_[side]; }

  std::vector<std::string> bodyRoles() const override { return {"lower_arm", "knuckle", "wheel"}; }
  double calcCornerMass(int side) const override;
  SimTK::Vec3 calcWheelCentreInChassis(int side) const override { return params_[side].spindle_m; }
  SimTK::UnitVec3 getSpinAxis(int side) const override { return params_[side].calcSpinAxis(side == 0); }
  double getSuspensionCoordinate(const SimTK::State& s, int side) const override;
  double calcLoopGap(const SimTK::State& s, int side) const override;
  bool isSteerable() const override { return params_[0].tie_rod == "none" && params_[1].tie_rod == "none"; }
  bool usesRack() const override { return params_[0].tie_rod == "rack"; }
  bool getKinematicCorner(int side, KinematicCorner* k) const override {
    const MacPhersonStrutCorner& c = corners_[side];
    *k = {c.lower_arm, {c.upright.getMobilizedBodyIndex()}, c.upright, c.wheel, c.spring};
    return true;
  }

 protected:
  void DoBuildCorner(Scene& scene, SimTK::MobilizedBody& chassis, int side, const std::string& prefix) override;
  void DoShiftChassisFrame(const SimTK::Vec3& offset_m) override;

 private:
  MacPhersonStrutParams params_[2];
  MacPhersonStrutCorner corners_[2];
};

/// Registers "macpherson_strut" (registerSuspensionTemplates calls it).
void registerMacPhersonStrut(PluginRegistry& registry);

}  // namespace vdyn
