// The double-wishbone suspension templates (vdyn/templates/double_wishbone.h).
#include "vdyn/templates/double_wishbone.h"

namespace vdyn {

namespace {

/// The right corner's data, and the left one's where the block gives "left"
/// (a whole corner in the left side's own coordinates; default: the mirror).
struct WishboneAxleData {
  DoubleWishboneParams right;
  bool hasLeft = false;
  DoubleWishboneParams left;
};

WishboneAxleData readWishboneAxle(const ParamReader& r) {
  WishboneAxleData d;
  d.right = DoubleWishboneSuspension::fields().read(r);
  d.right.validate(r.where());
  if (r.has("left") && !r.child("left").json().empty()) {
    const ParamReader l = r.child("left");
    d.hasLeft = true;
    d.left = DoubleWishboneSuspension::fields().read(l);
    l.requireAllKeysRead();
    d.left.validate(l.where());
  }
  return d;
}

TypeInfo wishboneInfo(const std::string& summary) {
  TypeInfo t = typeInfo(summary, DoubleWishboneSuspension::fields());
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
                   "constraint rows, starts from double_wishbone's assembly, supports forward_dynamics \"dense\""));
}


// --- double_wishbone ---------------------------------------------------------

const FieldTable<DoubleWishboneParams>& DoubleWishboneSuspension::fields() { return DoubleWishboneParams::fields(); }

void DoubleWishboneSuspension::setLeftCorner(const DoubleWishboneParams& left) { params_[1] = left; }

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
  const JointParams& j = params_[side].upper_ball;
  return (corners_[side].upper_arm.findStationLocationInGround(s, j.parent_point_m) -
          corners_[side].knuckle.findStationLocationInGround(s, j.child_point_m))
      .norm();
}

void DoubleWishboneSuspension::DoBuildCorner(Scene& scene, SimTK::MobilizedBody& chassis, int side,
                                             const std::string& prefix) {
  corners_[side] = buildDoubleWishbone(scene, chassis, params_[side], prefix);
}

// --- double_wishbone_reduced -------------------------------------------------

ReducedDoubleWishboneSuspension::ReducedDoubleWishboneSuspension(const DoubleWishboneParams& right)
    : DoubleWishboneSuspension("double_wishbone_reduced", right) {}

void ReducedDoubleWishboneSuspension::DoBuildCorner(Scene& scene, SimTK::MobilizedBody& chassis, int side,
                                                    const std::string& prefix) {
  loops_[side] = std::make_unique<WishboneLoop>(params_[side]);
  reduced_[side] = buildReducedWishbone(scene, chassis, params_[side], *loops_[side], prefix);
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
  *arm = {reduced_[side].lower_arm, reduced_[side].upper_arm, reduced_[side].knuckle, loops_[side].get()};
  return true;
}

}  // namespace vdyn
