// The double-wishbone suspension templates (vdyn/templates/double_wishbone.h).
#include "vdyn/templates/double_wishbone.h"

#include <algorithm>
#include <cmath>

namespace vdyn {

namespace {

/// The right corner's data, and the left one's where the block gives "left"
/// (a whole corner in the left side's own coordinates; default: the mirror).
struct WishboneAxleData {
  DoubleWishboneParams right;
  bool hasLeft = false;
  DoubleWishboneParams left;
};

/// One corner in either form: chassis-frame hardpoints ("hardpoints_m"
/// given, DoubleWishboneParams::fromHardpoints) or App. A's body-frame joints.
DoubleWishboneParams readCorner(const ParamReader& r) {
  if (r.has("hardpoints_m") && !r.raw("hardpoints_m").is_null()) {
    if (r.has("joints")) throw Error(r.at("joints") + ": give either joints (body frames) or hardpoints_m, not both");
    return DoubleWishboneParams::fromHardpoints(r);
  }
  // The hardpoint form's own keys, at their defaults or absent.
  if (r.stringOr("tie_rod", "none") != "none" || r.numberOr("camber_rad", 0) != 0 || r.numberOr("toe_in_rad", 0) != 0)
    throw Error(r.where() + ": tie_rod, camber_rad and toe_in_rad belong to the hardpoints_m form (the body-frame "
                            "form gives joints.wheel_spin_axis)");
  DoubleWishboneParams p = DoubleWishboneSuspension::fields().read(r);
  p.validate(r.where());
  return p;
}

WishboneAxleData readWishboneAxle(const ParamReader& r) {
  WishboneAxleData d;
  d.right = readCorner(r);
  if (r.has("left") && !r.child("left").json().empty()) {
    const ParamReader l = r.child("left");
    d.hasLeft = true;
    d.left = readCorner(l);
    l.requireAllKeysRead();
  }
  return d;
}

TypeInfo wishboneInfo(const std::string& summary) {
  TypeInfo t = typeInfo(summary, DoubleWishboneSuspension::fields());
  for (FieldInfo& f : t.fields)
    if (f.key == "joints") f.meaning = "(body-frame form, App. A) " + f.meaning;
  t.fields.push_back({"hardpoints_m", "m", "null",
                      "(hardpoint form, a published car's) chassis frame at design: lca_front, lca_back, lca_upright, "
                      "uca_front, uca_back, uca_upright, spindle, spring_chassis, spring_arm; optional damper_chassis, "
                      "damper_arm, tierod_chassis, tierod_upright; then bodies lower_arm, upper_arm, knuckle carry "
                      "com_m (chassis frame) and joints is not given"});
  t.fields.push_back({"tie_rod", "-", "\"none\"",
                      "(hardpoint form) none (the knuckle steers freely, for a steering plugin) | chassis (a "
                      "fixed-length rod tierod_chassis - tierod_upright holds it) | rack (the same rod, its inner end "
                      "on the axle's steering rack: the axle needs a \"steering\" block)"});
  t.fields.push_back({"camber_rad", "rad", "0", "(hardpoint form) static camber, + top of the wheel outward"});
  t.fields.push_back({"toe_in_rad", "rad", "0", "(hardpoint form) static toe, + toe-in"});
  t.fields.push_back({"left", "-", "{}",
                      "the left corner's bodies, joints and spring in its own coordinates, where it is not the mirror "
                      "of the right (eta -> -eta); {} or absent: the mirror"});
  return t;
}

template <class S>
std::unique_ptr<Suspension> makeWishbone(const ParamReader& r, const NoContext&) {
  const WishboneAxleData d = readWishboneAxle(r);
  auto s = std::make_unique<S>(d.right);
  if (d.hasLeft) s->setLeftCorner(d.left);
  return s;
}

}  // namespace

void registerDoubleWishboneTemplates(PluginRegistry& registry) {
  registry.addChoice<Suspension>(
      kSuspensionFamily, "double_wishbone", makeWishbone<DoubleWishboneSuspension>,
      wishboneInfo("double wishbone (App. A): lower and upper A-arm on revolute chassis joints, knuckle on a ball "
                   "joint, the loop closed by a ball constraint at the upper ball joint; spring-damper chassis to "
                   "lower arm; bodies lower_arm, knuckle, upper_arm, wheel"));
  registry.addChoice<Suspension>(
      kSuspensionFamily, "double_wishbone_reduced", makeWishbone<ReducedDoubleWishboneSuspension>,
      wishboneInfo("the same double wishbone with the loop solved in the knuckle's mobilizer (q = s, delta): fewer "
                   "constraint rows, starts from double_wishbone's assembly, has dense rows; the vehicle's \"formulation\" "
                   "builds it from a double_wishbone block (auto, reduced, dense) or the reverse (constrained)"));
}


// --- double_wishbone ---------------------------------------------------------

const FieldTable<DoubleWishboneParams>& DoubleWishboneSuspension::fields() { return DoubleWishboneParams::fields(); }

void DoubleWishboneSuspension::setLeftCorner(const DoubleWishboneParams& left) {
  // One rack moves both tie rods: both corners on it or neither.
  if ((left.tie_rod == "rack") != (params_[0].tie_rod == "rack"))
    throw Error(templateName() + ": left.tie_rod \"" + left.tie_rod + "\" and the right corner's \"" +
                params_[0].tie_rod + "\": a rack takes both corners' tie rods or neither");
  params_[1] = left;
}

void DoubleWishboneSuspension::DoShiftChassisFrame(const SimTK::Vec3& d) {
  for (DoubleWishboneParams& p : params_) {
    for (JointParams* j : {&p.lower_pivot, &p.upper_pivot}) {
      j->parent_point_m += d;
      j->parent_axis_point_m += d;
    }
    p.spring_chassis_point_m += d;
    p.damper_chassis_point_m += d;
    p.tierod_chassis_point_m += d;
  }
}

double DoubleWishboneSuspension::calcCornerMass(int side) const {
  const DoubleWishboneParams& c = params_[side];
  return c.lower_arm.mass_kg + c.knuckle.mass_kg + c.upper_arm.mass_kg + c.wheel.mass_kg;
}

SimTK::Vec3 DoubleWishboneSuspension::calcWheelCentreInChassis(int side) const {
  return wheelCentreInChassis(params_[side]);
}

SimTK::UnitVec3 DoubleWishboneSuspension::getSpinAxis(int side) const {
  return SimTK::UnitVec3(params_[side].wheel_spin_axis);
}

double DoubleWishboneSuspension::getSuspensionCoordinate(const SimTK::State& s, int side) const {
  return corners_[side].lower_arm.getOneQ(s, 0);
}

double DoubleWishboneSuspension::calcLoopGap(const SimTK::State& s, int side) const {
  const DoubleWishboneParams& p = params_[side];
  const JointParams& j = p.upper_ball;
  double gap = (corners_[side].upper_arm.findStationLocationInGround(s, j.parent_point_m) -
                corners_[side].knuckle.findStationLocationInGround(s, j.child_point_m))
                   .norm();
  if (p.tie_rod != "none") {
    const SimTK::MobilizedBody& chassis =
        p.tie_rod == "rack" ? getRack() : corners_[side].lower_arm.getParentMobilizedBody();
    const double length = (wheelCentreInChassis(p) + p.tierod_knuckle_point_m - p.tierod_chassis_point_m).norm();
    gap = std::max(gap, std::abs((corners_[side].knuckle.findStationLocationInGround(s, p.tierod_knuckle_point_m) -
                                  chassis.findStationLocationInGround(s, p.tierod_chassis_point_m))
                                     .norm() -
                                 length));
  }
  return gap;
}

bool DoubleWishboneSuspension::getKinematicCorner(int side, KinematicCorner* k) const {
  const DoubleWishboneCorner& c = corners_[side];
  *k = {c.lower_arm, {c.knuckle.getMobilizedBodyIndex(), c.upper_arm.getMobilizedBodyIndex()}, c.knuckle, c.wheel,
        c.spring};
  return true;
}

Suspension::SpringMount DoubleWishboneSuspension::springMount(const SimTK::MobilizedBody& chassis,
                                                             const SimTK::MobilizedBody& lowerArm,
                                                             const DoubleWishboneParams& p) {
  return {chassis, p.spring_chassis_point_m, lowerArm, p.spring_arm_point_m};
}

void DoubleWishboneSuspension::DoBuildCorner(Scene& scene, SimTK::MobilizedBody& chassis, int side,
                                             const std::string& prefix) {
  corners_[side] = buildDoubleWishbone(scene, chassis, params_[side], prefix,
                                       params_[side].tie_rod == "rack" ? &getRack() : nullptr);
  addSpringMount(scene, side, prefix, springMount(chassis, corners_[side].lower_arm, params_[side]),
                 params_[side].stops);
}

std::string DoubleWishboneSuspension::DoGetReducedTemplate(std::string* whyNot) const {
  for (const DoubleWishboneParams& p : params_)
    if (p.tie_rod != "none") {
      *whyNot = templateName() + " with tie_rod \"" + p.tie_rod +
                "\" has no reduced form (the reduced knuckle's steering angle is a mobility)";
      return "";
    }
  return "double_wishbone_reduced";
}

// --- double_wishbone_reduced -------------------------------------------------

ReducedDoubleWishboneSuspension::ReducedDoubleWishboneSuspension(const DoubleWishboneParams& right)
    : DoubleWishboneSuspension("double_wishbone_reduced", right) {
  if (right.tie_rod != "none")
    throw Error("double_wishbone_reduced: tie_rod \"" + right.tie_rod +
                "\" is not in its reduced loop (delta is a mobility); use double_wishbone");
}

void ReducedDoubleWishboneSuspension::DoBuildCorner(Scene& scene, SimTK::MobilizedBody& chassis, int side,
                                                    const std::string& prefix) {
  loops_[side] = std::make_unique<WishboneLoop>(params_[side]);
  reduced_[side] = buildReducedWishbone(scene, chassis, params_[side], *loops_[side], prefix);
  addSpringMount(scene, side, prefix, springMount(chassis, reduced_[side].lower_arm, params_[side]),
                 params_[side].stops);
}

double ReducedDoubleWishboneSuspension::getSuspensionCoordinate(const SimTK::State& s, int side) const {
  return reduced_[side].lower_arm.getOneQ(s, 0);
}

void ReducedDoubleWishboneSuspension::setPositionFrom(SimTK::State& s, int side, const Suspension& from,
                                                      const SimTK::State& fs, double delta_rad) const {
  setReducedCornerPosition(s, reduced_[side], from.getSuspensionCoordinate(fs, side), delta_rad);
}

std::vector<ArmPlanesImpl::Row> ReducedDoubleWishboneSuspension::getArmRows(int side) const {
  return armPlaneRows(params_[side], reduced_[side].lower_arm, reduced_[side].knuckle, reduced_[side].upper_arm);
}

bool ReducedDoubleWishboneSuspension::getDenseArm(int side, ReducedDenseRows::Arm* arm) const {
  *arm = {reduced_[side].lower_arm, reduced_[side].upper_arm, reduced_[side].knuckle,
          reduced_[side].knuckle_mobilizer};
  return true;
}

}  // namespace vdyn
