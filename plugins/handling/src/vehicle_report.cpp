#include "vdyn/handling/vehicle_report.h"

#include <algorithm>
#include <cmath>
#include "vdyn/core/threads.h"

namespace vdyn {

using SimTK::Vec3;

namespace {
struct CornerGeometry {
  Vec3 centre, contact, spin;  // in ground (the chassis is held at rest)
  double energy;               // spring potential energy, J
};
}  // namespace

std::vector<KinematicsPoint> calcSuspensionKinematics(const Scene& scene, const SimTK::State& rest,
                                                      const SuspensionCorner& c, const std::vector<double>& travels,
                                                      double road) {
  const SimTK::MultibodySystem& system = scene.getSystem();
  const SimTK::SimbodyMatterSubsystem& matter = scene.getMatter();
  SimTK::State s = rest;
  s.updU() = 0;
  system.realize(s, SimTK::Stage::Position);
  const std::string who = "suspension kinematics of corner '" + c.name + "'";
  if (c.lower_arm.getNumQ(s) != 1) throw Error(who + ": the lower arm must have one coordinate");
  // The contact point: on the wheel plane below the centre at rest, fixed in the knuckle.
  const Vec3 centre0 = c.wheel.getBodyOriginLocation(s);
  const Vec3 spin0 = c.wheel.getBodyRotation(s) * Vec3(c.spin_axis_W);
  // Down in the wheel plane: -z with its component along the spin axis removed.
  Vec3 down = Vec3(0, 0, -1) - SimTK::dot(Vec3(0, 0, -1), spin0) * spin0;
  down = down / down.norm();
  const double radius = (centre0[2] - road) / -down[2];
  const Vec3 contactK = c.knuckle.findStationAtGroundPoint(s, centre0 + radius * down);
  const Vec3 wheelK = c.knuckle.findStationAtGroundPoint(s, centre0);
  const double side = centre0[1] > c.centre_plane_y_m ? 1.0 : -1.0;  // + left
  const double theta0 = c.lower_arm.getOneQ(s, 0);

  // Only the constraints on the corner's free bodies take part (the others'
  // bodies are locked: their equations would leave the assembler without
  // degrees of freedom).
  for (SimTK::ConstraintIndex ci(0); ci < matter.getNumConstraints(); ++ci) {
    const SimTK::Constraint& con = matter.getConstraint(ci);
    bool mine = false;
    for (SimTK::ConstrainedBodyIndex cb(0); cb < con.getNumConstrainedBodies(); ++cb)
      mine |= std::find(c.free.begin(), c.free.end(), con.getMobilizedBodyFromConstrainedBody(cb).getMobilizedBodyIndex()) !=
              c.free.end();
    if (!mine && !con.isDisabled(s)) con.disable(s);
  }
  system.realize(s, SimTK::Stage::Position);
  SimTK::Assembler assembler(system);
  assembler.setAccuracy(1e-12);
  for (SimTK::MobilizedBodyIndex b(1); b < matter.getNumBodies(); ++b)
    if (std::find(c.free.begin(), c.free.end(), b) == c.free.end()) assembler.lockMobilizer(b);
  auto at = [&](double theta) {
    c.lower_arm.setOneQ(s, 0, theta);
    try {
      assembler.initialize(s);
      const auto lock = lockSimbodyAssembler();  // Simbody's Ipopt is not thread-safe (vdyn/core/threads.h)
      assembler.assemble(s);
      assembler.updateFromInternalState(s);
    } catch (const std::exception& e) {
      throw Error(who + ": assembly failed at lower-arm angle " + formatValue(theta) + " rad: " + e.what());
    }
    system.realize(s, SimTK::Stage::Position);
    CornerGeometry g;
    g.centre = c.knuckle.findStationLocationInGround(s, wheelK);
    g.contact = c.knuckle.findStationLocationInGround(s, contactK);
    g.spin = c.wheel.getBodyRotation(s) * Vec3(c.spin_axis_W);
    g.energy = c.spring.calcPotentialEnergyContribution(s);
    return g;
  };
  // Lower-arm angle for a travel: secant iteration on the wheel-centre height.
  auto solveTravel = [&](double travel, double thetaGuess) {
    double t0 = thetaGuess, t1 = thetaGuess + 1e-3;
    double f0 = at(t0).centre[2] - centre0[2] - travel, f1 = at(t1).centre[2] - centre0[2] - travel;
    for (int it = 0; it < 50 && std::abs(f1) > 1e-12; ++it) {
      if (f1 == f0) break;
      const double t2 = t1 - f1 * (t1 - t0) / (f1 - f0);
      t0 = t1, f0 = f1, t1 = t2;
      f1 = at(t1).centre[2] - centre0[2] - travel;
    }
    if (!(std::abs(f1) <= 1e-9))
      throw Error(who + ": wheel travel " + formatValue(travel) + " m not reached (the linkage may lock), off by " +
                  formatValue(f1) + " m");
    return t1;
  };
  std::vector<KinematicsPoint> out;
  double theta = theta0;
  for (double z : travels) {
    requireFinite(z, "wheel travel_m");
    theta = solveTravel(z, theta);
    const CornerGeometry g = at(theta);
    KinematicsPoint p;
    p.travel_m = z;
    Vec3 sp = g.spin;
    if (sp[1] < 0) sp = -sp;  // spin axis pointing left
    p.camber_rad = -side * std::asin(sp[2]);
    const Vec3 h = SimTK::cross(sp, Vec3(0, 0, 1));
    p.toe_rad = -side * std::atan2(h[1], h[0]);
    p.track_change_m = side * (g.contact[1] - (centre0 + radius * down)[1]);
    p.recession_m = -(g.centre[0] - centre0[0]);
    // Wheel rate and the contact point's path by central differences of +-1 mm.
    const double dz = 1e-3;
    const double tp = solveTravel(z + dz, theta), tm = solveTravel(z - dz, theta);
    const CornerGeometry gp = at(tp), gm = at(tm);
    p.wheel_rate_N_per_m = (gp.energy - 2 * g.energy + gm.energy) / (dz * dz);
    const double dy = (gp.contact[1] - gm.contact[1]) / (2 * dz), dzc = (gp.contact[2] - gm.contact[2]) / (2 * dz);
    // Instant centre line through the contact point C, normal to its velocity
    // (dy, dzc); at the centre plane y = y0: z = z_C + (y_C - y0) dy / dzc.
    p.roll_centre_height_m = g.contact[2] + (g.contact[1] - c.centre_plane_y_m) * dy / dzc - road;
    out.push_back(p);
  }
  return out;
}

}  // namespace vdyn
