#pragma once
// The suspension templates "double_wishbone" and "double_wishbone_reduced":
// the seed's App. A corner (vdyn/vehicles/double_wishbone.h) in its two
// formulations, one data block (bodies, joints, spring) for both.
#include <memory>
#include <string>

#include "vdyn/vehicles/double_wishbone.h"
#include "vdyn/vehicles/reduced_wishbone.h"
#include "vdyn/vehicles/suspension.h"

namespace vdyn {

/// "double_wishbone": the loop cut at the upper ball joint and closed by a
/// Constraint::Ball (the reference model; double_wishbone.h).
class DoubleWishboneSuspension : public Suspension {
 public:
  /// `right` is the right corner; the left one is its mirror.
  explicit DoubleWishboneSuspension(const DoubleWishboneParams& right)
      : DoubleWishboneSuspension("double_wishbone", right) {}
  /// The keys of one corner ("bodies", "joints", "spring"; double_wishbone.h).
  static const FieldTable<DoubleWishboneParams>& fields();
  /// Replaces the mirrored left corner (data key "left"); before build().
  void setLeftCorner(const DoubleWishboneParams& left);

  const DoubleWishboneParams& getCornerParams(int side) const { return params_[side]; }
  /// The built corner (after build(); this template only, not the reduced one).
  const DoubleWishboneCorner& getCorner(int side) const { return corners_[side]; }

  std::vector<std::string> bodyRoles() const override { return {"lower_arm", "knuckle", "upper_arm", "wheel"}; }
  double calcCornerMass(int side) const override;
  SimTK::Vec3 calcWheelCentreInChassis(int side) const override;
  SimTK::UnitVec3 getSpinAxis(int side) const override;
  double getSuspensionCoordinate(const SimTK::State& s, int side) const override;
  double calcLoopGap(const SimTK::State& s, int side) const override;
  bool getKinematicCorner(int side, KinematicCorner* k) const override;
  bool isSteerable() const override { return params_[0].tie_rod == "none" && params_[1].tie_rod == "none"; }
  bool usesRack() const override { return params_[0].tie_rod == "rack"; }

 protected:
  DoubleWishboneSuspension(std::string name, const DoubleWishboneParams& right)
      : Suspension(std::move(name)), params_{right, right.mirrored()} {}
  void DoBuildCorner(Scene& scene, SimTK::MobilizedBody& chassis, int side, const std::string& prefix) override;
  void DoShiftChassisFrame(const SimTK::Vec3& offset_m) override;
  /// "double_wishbone_reduced" when no tie rod holds the knuckles (the reduced
  /// knuckle's delta is a mobility); none with a tie rod.
  std::string DoGetReducedTemplate(std::string* whyNot) const override;
  /// The spring's mounts of a built corner: the chassis point and the lower arm's.
  static SpringMount springMount(const SimTK::MobilizedBody& chassis, const SimTK::MobilizedBody& lowerArm,
                                 const DoubleWishboneParams& p);
  DoubleWishboneParams params_[2];

 private:
  DoubleWishboneCorner corners_[2];
};

/// "double_wishbone_reduced": the same mechanism with the loop solved in the
/// knuckle's mobilizer, q = [s, delta] (reduced_wishbone.h); it starts from
/// the constrained model's assembly and supports the dense path.
class ReducedDoubleWishboneSuspension : public DoubleWishboneSuspension {
 public:
  explicit ReducedDoubleWishboneSuspension(const DoubleWishboneParams& right);

  const ReducedWishboneCorner& getReducedCorner(int side) const { return reduced_[side]; }
  const WishboneLoop& getLoop(int side) const { return *loops_[side]; }

  double getSuspensionCoordinate(const SimTK::State& s, int side) const override;
  double calcLoopGap(const SimTK::State&, int) const override { return 0; }
  std::string getAssemblyTemplate() const override { return "double_wishbone"; }
  void setPositionFrom(SimTK::State& s, int side, const Suspension& from, const SimTK::State& fs,
                       double delta_rad) const override;
  std::vector<ArmPlanesImpl::Row> getArmRows(int side) const override;
  bool getDenseArm(int side, ReducedDenseRows::Arm* arm) const override;
  bool getKinematicCorner(int, KinematicCorner*) const override { return false; }

 protected:
  void DoBuildCorner(Scene& scene, SimTK::MobilizedBody& chassis, int side, const std::string& prefix) override;
  std::string DoGetReducedTemplate(std::string*) const override { return templateName(); }

 private:
  std::unique_ptr<WishboneLoop> loops_[2];
  ReducedWishboneCorner reduced_[2];
};

/// Registers both templates (registerSuspensionTemplates calls it).
void registerDoubleWishboneTemplates(PluginRegistry& registry);

}  // namespace vdyn
