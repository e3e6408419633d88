// The "torsion_bar" anti-roll bar template (vdyn/templates/torsion_bar.h).
#include "vdyn/templates/torsion_bar.h"

#include <cmath>

namespace vdyn {

using SimTK::Vec3;

void TorsionBarParams::validate(const ParamReader& r) const {
  requirePositive(stiffness_N_m_per_rad, r.at("stiffness_N_m_per_rad"));
  requireNonNegative(damping_N_m_s_per_rad, r.at("damping_N_m_s_per_rad"));
  requirePositive(lever_m, r.at("lever_m"));
  for (int i = 0; i < 3; ++i) requireFinite(attach_point_m[i], r.at("attach_point_m"));
  if (role.empty()) throw Error(r.at("role") + ": empty body role");
}

const FieldTable<TorsionBarParams>& TorsionBarParams::fields() {
  using P = TorsionBarParams;
  static const auto t =
      FieldTable<P>()
          .number("stiffness_N_m_per_rad", &P::stiffness_N_m_per_rad, "N m/rad", "torsional stiffness k_t of the bar",
                  true)
          .number("damping_N_m_s_per_rad", &P::damping_N_m_s_per_rad, "N m s/rad", "torsional damping c_t")
          .number("lever_m", &P::lever_m, "m", "length L of each arm (the lever to its droplink)", true)
          .vec3("attach_point_m", &P::attach_point_m, "m",
                "the right droplink's point on the right corner's body of `role`, in that body's frame (the left "
                "one mirrored, eta -> -eta)")
          .string("role", &P::role, "suspension body role the droplinks attach to (lower_arm, ...)");
  return t;
}

namespace {

/// The force element: self-contained (it lives with the scene's system).
class TorsionBarForce : public SimTK::Force::Custom::Implementation {
 public:
  TorsionBarForce(const SimTK::MobilizedBody& chassis, const SimTK::MobilizedBody (&bodies)[2],
                  const Vec3 (&points)[2], const double (&designZ)[2], const TorsionBarParams& p, std::string what)
      : chassis_(chassis), bodies_{bodies[0], bodies[1]}, points_{points[0], points[1]},
        designZ_{designZ[0], designZ[1]}, k_(p.stiffness_N_m_per_rad), c_(p.damping_N_m_s_per_rad), L_(p.lever_m),
        what_(std::move(what)) {}

  /// dz_s and its rate (rate only if `rate`), the attachment points in ground.
  struct Kin {
    double dz[2], dzdot[2] = {0, 0}, root[2];  // root = sqrt(L^2 - dz^2)
    Vec3 p_G[2];
  };
  Kin calcKin(const SimTK::State& s, bool rate) const {
    Kin k;
    const Vec3 z_G = chassis_.getBodyRotation(s).z();
    for (int i = 0; i < 2; ++i) {
      k.p_G[i] = bodies_[i].findStationLocationInGround(s, points_[i]);
      const Vec3 p_C = chassis_.findStationAtGroundPoint(s, k.p_G[i]);
      k.dz[i] = p_C[2] - designZ_[i];
      if (!(std::abs(k.dz[i]) < L_))
        throw Error(what_ + ": the " + (i == 0 ? "right" : "left") + " droplink's travel dz = " +
                    formatValue(k.dz[i]) + " m reached the lever_m " + formatValue(L_) + " m");
      k.root[i] = std::sqrt(L_ * L_ - k.dz[i] * k.dz[i]);
      if (rate)
        k.dzdot[i] = SimTK::dot(z_G, bodies_[i].findStationVelocityInGround(s, points_[i]) -
                                         chassis_.findStationVelocityInGround(s, p_C));
    }
    return k;
  }
  double twist(const Kin& k) const { return std::asin(k.dz[0] / L_) - std::asin(k.dz[1] / L_); }
  double twistRate(const Kin& k) const { return k.dzdot[0] / k.root[0] - k.dzdot[1] / k.root[1]; }
  double calcTwist(const SimTK::State& s) const { return twist(calcKin(s, false)); }
  double calcTorque(const SimTK::State& s) const {
    const Kin k = calcKin(s, c_ != 0);
    return k_ * twist(k) + (c_ != 0 ? c_ * twistRate(k) : 0.0);
  }

  void calcForce(const SimTK::State& s, SimTK::Vector_<SimTK::SpatialVec>& bodyForces, SimTK::Vector_<Vec3>&,
                 SimTK::Vector&) const override {
    const Kin k = calcKin(s, c_ != 0);
    const double T = k_ * twist(k) + (c_ != 0 ? c_ * twistRate(k) : 0.0);
    const Vec3 z_G = chassis_.getBodyRotation(s).z();
    const double F[2] = {-T / k.root[0], T / k.root[1]};
    for (int i = 0; i < 2; ++i) {
      bodies_[i].applyForceToBodyPoint(s, points_[i], F[i] * z_G, bodyForces);
      chassis_.applyForceToBodyPoint(s, chassis_.findStationAtGroundPoint(s, k.p_G[i]), -F[i] * z_G, bodyForces);
    }
  }
  SimTK::Real calcPotentialEnergy(const SimTK::State& s) const override {
    const double phi = calcTwist(s);
    return 0.5 * k_ * phi * phi;
  }
  bool dependsOnlyOnPositions() const override { return c_ == 0; }

 private:
  SimTK::MobilizedBody chassis_;
  SimTK::MobilizedBody bodies_[2];
  Vec3 points_[2];
  double designZ_[2];
  double k_, c_, L_;
  std::string what_;
};

/// The body's frame in the chassis frame with every mobilizer between them at
/// q = 0 (the tabulated configuration the templates build to).
SimTK::Transform tabulatedPoseInChassis(const SimTK::MobilizedBody& chassis, SimTK::MobilizedBody b,
                                        const std::string& where) {
  SimTK::Transform X_CB;
  while (b.getMobilizedBodyIndex() != chassis.getMobilizedBodyIndex()) {
    if (b.isGround()) throw Error(where + ": the droplink's body is not outboard of the chassis");
    // X_PB = X_PF X_FM(q = 0) X_MB with X_FM(0) = identity.
    X_CB = b.getDefaultInboardFrame() * ~b.getDefaultOutboardFrame() * X_CB;
    b = b.getParentMobilizedBody();
  }
  return X_CB;
}

}  // namespace

AntiRollBar::Measures TorsionBar::DoBuild(Scene& scene, const SimTK::MobilizedBody& chassis,
                                          const Suspension& suspension, const std::string& axle,
                                          const std::string& where) {
  if (!suspension.hasBodyRole(p_.role)) {
    std::string known;
    for (const std::string& r : suspension.bodyRoles()) known += (known.empty() ? "" : ", ") + r;
    throw Error(where + " role: axle '" + axle + "' anti_roll_bar template '" + templateName() +
                "' attaches to role '" + p_.role + "', which its suspension template '" + suspension.templateName() +
                "' does not have (roles: " + known + ")");
  }
  const SimTK::MobilizedBody bodies[2] = {suspension.getBody(0, p_.role), suspension.getBody(1, p_.role)};
  const Vec3 points[2] = {p_.attach_point_m, Vec3(p_.attach_point_m[0], -p_.attach_point_m[1], p_.attach_point_m[2])};
  double designZ[2];
  for (int i = 0; i < 2; ++i) designZ[i] = (tabulatedPoseInChassis(chassis, bodies[i], where) * points[i])[2];
  auto* impl = new TorsionBarForce(chassis, bodies, points, designZ, p_, where + " (axle '" + axle + "')");
  const SimTK::Force::Custom force(scene.updForces(), impl);  // the force subsystem owns impl
  const TorsionBarForce* f = impl;
  return {[f](const SimTK::State& s) { return f->calcTwist(s); },
          [f](const SimTK::State& s) { return f->calcTorque(s); },
          {force.getForceIndex()}};
}

void registerTorsionBarTemplate(PluginRegistry& registry) {
  registry.addChoice<AntiRollBar>(
      kAntiRollBarFamily, "torsion_bar",
      [](const ParamReader& r, const NoContext&) -> std::unique_ptr<AntiRollBar> {
        const TorsionBarParams p = TorsionBarParams::fields().read(r);
        p.validate(r);
        return std::make_unique<TorsionBar>(p);
      },
      typeInfo("anti-roll bar: a massless torsion bar (k_t, c_t) whose arms of length L are joined by droplinks "
               "acting along the chassis z axis to a point on each side's suspension body of `role`; V = 1/2 k_t "
               "phi^2, phi = asin(dz_R/L) - asin(dz_L/L); outputs <axle>_arb.twist_rad, <axle>_arb.torque_N_m",
               TorsionBarParams::fields()));
}

}  // namespace vdyn
