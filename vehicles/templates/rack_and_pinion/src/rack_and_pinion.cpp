// The rack-and-pinion steering template (vdyn/templates/rack_and_pinion.h).
#include "vdyn/templates/rack_and_pinion.h"

#include <algorithm>
#include <cmath>

#include "vdyn/core/error.h"
#include "vdyn/core/threads.h"
#include "vdyn/steering/steering.h"

namespace vdyn {

using SimTK::Vec3;

void RackAndPinionParams::validate(const std::string& w) const {
  if (!std::isfinite(travel_per_pinion_rad_m) || travel_per_pinion_rad_m == 0)
    throw Error(w + ".rack_travel_per_pinion_rad_m must be a finite non-zero number (m/rad, signed), got " +
                formatValue(travel_per_pinion_rad_m));
  requirePositive(rack_mass_kg, w + ".rack_mass_kg");
  requirePositive(rack_inertia_kg_m2, w + ".rack_inertia_kg_m2");
  requirePositive(travel_limit_m, w + ".rack_travel_limit_m");
  for (int i = 0; i < 3; ++i) requireFinite(location_m[i], w + ".location_m");
}

const FieldTable<RackAndPinionParams>& RackAndPinionParams::fields() {
  using P = RackAndPinionParams;
  static const auto t =
      FieldTable<P>()
          .number("rack_travel_per_pinion_rad_m", &P::travel_per_pinion_rad_m, "m/rad",
                  "c: rack travel (chassis +y) per +1 rad of steering-wheel angle (+ = steering left); signed, c < 0 "
                  "with the tie rods behind the axle",
                  true)
          .number("rack_mass_kg", &P::rack_mass_kg, "kg", "rack body mass", true)
          .number("rack_inertia_kg_m2", &P::rack_inertia_kg_m2, "kg m^2",
                  "rack moment of inertia about each axis through its c.m.")
          .vec3("location_m", &P::location_m, "m", "rack c.m. at zero travel, chassis frame")
          .number("rack_travel_limit_m", &P::travel_limit_m, "m",
                  "largest |rack travel| a steering command may ask (beyond it: an error)");
  return t;
}

RackAndPinion::RackAndPinion(const RackAndPinionParams& p, std::string where) : p_(p), where_(std::move(where)) {
  p_.validate(where_);
}

const SimTK::MobilizedBody::Slider& RackAndPinion::build(Scene& scene, SimTK::MobilizedBody& chassis,
                                                          const std::string& bodyName) {
  // Simbody's Slider translates along its frames' x: both frames turn x onto
  // the chassis y, so at q = 0 the rack frame is the chassis frame and q is
  // the travel along chassis +y.
  const SimTK::Rotation xToY(SimTK::UnitVec3(SimTK::YAxis), SimTK::XAxis);
  const Vec3 c = p_.location_m;
  const SimTK::Body::Rigid body(SimTK::MassProperties(
      p_.rack_mass_kg, c, SimTK::Inertia(p_.rack_inertia_kg_m2).shiftFromMassCenter(c, p_.rack_mass_kg)));
  slider_ = SimTK::MobilizedBody::Slider(chassis, SimTK::Transform(xToY), body, SimTK::Transform(xToY));
  scene.addBody(bodyName, slider_);
  return slider_;
}

std::unique_ptr<RackAndPinion> makeSteeringTemplate(const PluginRegistry& registry, const ParamReader& block) {
  std::unique_ptr<RackAndPinion> s = registry.createChoice<RackAndPinion>(kSteeringFamily, block.string("template"),
                                                                          block, NoContext{}, block.at("template"));
  block.requireAllKeysRead();
  return s;
}

void registerSteeringTemplates(PluginRegistry& registry) {
  registry.addChoice<RackAndPinion>(
      kSteeringFamily, "rack_and_pinion",
      [](const ParamReader& r, const NoContext&) {
        return std::make_unique<RackAndPinion>(RackAndPinionParams::fields().read(r), r.where());
      },
      typeInfo("rack and pinion: a rack body on a slider along chassis y, rack travel = c * steering-wheel angle, "
               "tie rods from the rack to the uprights (the axle's suspension with tie_rod \"rack\"); a steering "
               "plugin on the axle drives it; overall ratio N0 at centre from the geometry",
               RackAndPinionParams::fields()));
}

// --- the kinematics rig -----------------------------------------------------

struct RackSteeringRig::Impl {
  Scene scene;
  std::unique_ptr<Suspension> susp;
  RackAndPinion rack;
  SimTK::State state;
  SimTK::MobilizedBody knuckle[2];
  SimTK::UnitVec3 spin[2];
  double x = 0;  ///< rack travel of `state`
  Impl(const RackAndPinionParams& p) : rack(p) {}
};

RackSteeringRig::RackSteeringRig(const Json& suspension, const std::string& where, const RackAndPinionParams& rack,
                                 const PluginRegistry& registry)
    : impl_(std::make_unique<Impl>(rack)) {
  Impl& m = *impl_;
  m.susp = makeSuspension(registry, ParamReader::fromJson(suspension, where));
  if (!m.susp->usesRack())
    throw Error(where + ": the suspension's tie rods are not on a rack (give it \"tie_rod\": \"rack\")");
  SimTK::MobilizedBody& ground = m.scene.updMatter().updGround();
  m.susp->setRack(m.rack.build(m.scene, ground, "rack"));
  const std::string prefixes[2] = {"r.", "l."};
  m.susp->build(m.scene, ground, prefixes, nullptr);
  for (int side = 0; side < 2; ++side) {
    m.knuckle[side] = m.susp->getBody(side, "knuckle");
    m.spin[side] = m.susp->getSpinAxis(side);
    // The wheel centre (the wheel body's origin) held at its design height.
    const double z = m.susp->calcWheelCentreInChassis(side)[2];
    SimTK::Constraint::PointInPlane(ground, SimTK::UnitVec3(SimTK::ZAxis), z,
                                    const_cast<SimTK::MobilizedBody&>(m.susp->getBody(side, "wheel")), Vec3(0));
  }
  m.state = m.scene.getDefaultState();
}

RackSteeringRig::~RackSteeringRig() = default;

RackSteerPose RackSteeringRig::solve(double target) {
  Impl& m = *impl_;
  const SimTK::MultibodySystem& sys = m.scene.getSystem();
  const SimTK::MobilizedBody::Slider& slider = m.rack.getBody();
  SimTK::State& s = m.state;
  const int steps = std::max(1, int(std::ceil(std::abs(target - m.x) / 0.002)));
  const double x0 = m.x;
  double err = 0;
  for (int i = 1; i <= steps; ++i) {
    const double x = x0 + (target - x0) * i / steps;
    slider.setOneQ(s, 0, x);
    SimTK::Assembler assembler(sys);
    assembler.lockMobilizer(slider.getMobilizedBodyIndex());
    assembler.setAccuracy(1e-13);
    try {
      const auto lock = lockSimbodyAssembler();
      assembler.assemble(s);
    } catch (const std::exception& e) {
      throw Error("rack steering rig: closing the loops at rack travel " + formatValue(x) + " m failed: " + e.what());
    }
    m.x = x;
  }
  sys.realize(s, SimTK::Stage::Position);
  err = s.getQErr().size() ? SimTK::max(SimTK::abs(s.getQErr())) : 0.0;
  // Velocities: the rack at unit speed, every other u from the loops'
  // velocity equations G u = 0 (least squares, minimum norm: the wheel spins,
  // on which no constraint depends, come out zero).
  const SimTK::SimbodyMatterSubsystem& matter = m.scene.getMatter();
  SimTK::Matrix G;
  matter.calcG(s, G);
  const int nu = s.getNU();
  const int ur = slider.getFirstUIndex(s);
  SimTK::Matrix A(G.nrow(), nu - 1);
  SimTK::Vector b(G.nrow());
  for (int r = 0; r < G.nrow(); ++r) {
    b[r] = -G(r, ur);
    for (int j = 0, k = 0; j < nu; ++j)
      if (j != ur) A(r, k++) = G(r, j);
  }
  SimTK::Vector sol;
  SimTK::FactorQTZ qtz(A);
  qtz.solve(b, sol);
  for (int j = 0, k = 0; j < nu; ++j) s.updU()[j] = (j == ur) ? 1.0 : sol[k++];
  sys.realize(s, SimTK::Stage::Velocity);
  RackSteerPose out;
  out.rack_travel_m = m.x;
  double angle[2], rate[2];
  const SimTK::MobilizedBody& ground = matter.getGround();
  for (int side = 0; side < 2; ++side) {
    const Vec3 f = m.knuckle[side].getBodyRotation(s) * m.spin[side].asVec3();
    const Vec3 fdot = SimTK::cross(m.knuckle[side].getBodyAngularVelocity(s), f);
    angle[side] = headingAngle(s, ground, m.knuckle[side], m.spin[side]);
    // d/dt atan2(-f_x, f_y) = (f_x fdot_y - f_y fdot_x) / (f_x^2 + f_y^2)
    rate[side] = (f[0] * fdot[1] - f[1] * fdot[0]) / (f[0] * f[0] + f[1] * f[1]);
  }
  out.steer_right_rad = angle[0];
  out.steer_left_rad = angle[1];
  out.steer_mean_rad = 0.5 * (angle[0] + angle[1]);
  out.dmean_drack_rad_per_m = 0.5 * (rate[0] + rate[1]);
  out.overall_ratio = 1.0 / (m.rack.params().travel_per_pinion_rad_m * out.dmean_drack_rad_per_m);
  // The velocity equations' residual belongs to the reported error too.
  const SimTK::Vector uerr = s.getUErr();
  err = std::max(err, uerr.size() ? SimTK::max(SimTK::abs(uerr)) : 0.0);
  out.loop_error = err;
  s.updU() = 0;
  return out;
}

}  // namespace vdyn
