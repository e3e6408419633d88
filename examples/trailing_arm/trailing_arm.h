#pragma once
// An out-of-tree suspension template (docs/plugin_guide.md, "Write a plugin"): the trailing
// arm. One arm on a revolute chassis joint whose axis runs through two chassis
// points (pivot_inner_m, pivot_outer_m, chassis frame); the wheel spins on the
// arm at spindle_m; a spring-damper from a chassis point to a point on the arm.
// The arm is also the knuckle (it carries the wheel's spin joint and does not
// steer: isSteerable() is false). Body frame: the arm's c.m. (bodies.lower_arm
// com_m, chassis frame) with chassis axes. Roles: lower_arm, knuckle (the same
// arm), wheel. The left corner is the mirror of the right.
#include <memory>
#include <string>

#include "vdyn/vehicles/suspension.h"
#include "vdyn/vehicles/double_wishbone.h"

namespace vdyn_example {

struct TrailingArmParams {
  vdyn::RigidBodyParams arm, wheel;
  SimTK::Vec3 arm_com_m{0, 0, 0};                     ///< chassis frame at design
  SimTK::Vec3 pivot_inner_m{0, 0, 0}, pivot_outer_m{0, 0, 0};  ///< the arm's pivot axis, chassis frame
  SimTK::Vec3 spindle_m{0, 0, 0};                     ///< wheel centre, chassis frame
  double spring_stiffness_N_per_m = 0, damper_N_s_per_m = 0, spring_free_length_m = 0;
  SimTK::Vec3 spring_chassis_point_m{0, 0, 0};        ///< chassis frame
  SimTK::Vec3 spring_arm_point_m{0, 0, 0};            ///< arm frame (from its c.m.)

  void validate(const std::string& where) const;
  static const vdyn::FieldTable<TrailingArmParams>& fields();
  TrailingArmParams mirrored() const;
};

class TrailingArmSuspension : public vdyn::Suspension {
 public:
  explicit TrailingArmSuspension(const TrailingArmParams& right);
  std::vector<std::string> bodyRoles() const override { return {"lower_arm", "knuckle", "wheel"}; }
  double calcCornerMass(int side) const override { return p_[side].arm.mass_kg + p_[side].wheel.mass_kg; }
  SimTK::Vec3 calcWheelCentreInChassis(int side) const override { return p_[side].spindle_m; }
  SimTK::UnitVec3 getSpinAxis(int) const override { return SimTK::UnitVec3(SimTK::YAxis); }
  double getSuspensionCoordinate(const SimTK::State& s, int side) const override { return arm_[side].getOneQ(s, 0); }
  bool isSteerable() const override { return false; }

 protected:
  void DoBuildCorner(vdyn::Scene& scene, SimTK::MobilizedBody& chassis, int side, const std::string& prefix) override;
  void DoShiftChassisFrame(const SimTK::Vec3& offset_m) override;

 private:
  TrailingArmParams p_[2];
  SimTK::MobilizedBody::Pin arm_[2];
};

/// Registers "trailing_arm" in the suspension_template family.
void registerTrailingArm(vdyn::PluginRegistry& registry);

}  // namespace vdyn_example
