// The independent suspension kinematics reference (tests/reference/) against
// closed forms, its own analytic Jacobian against central differences, and
// the BMW E90's front strut and rear double wishbone printed over +-80 mm.
#include "reference/suspension_kinematics.h"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <cmath>
#include <cstdio>
#include <fstream>
#include <string>

namespace kr = vdyn::kinematics_reference;
using kr::Vec3;

namespace {

constexpr double kTol = 1e-12;  // m and rad: the loops close to 1e-13
constexpr double kPi = 3.14159265358979323846;

// Right-hand planar MacPherson: lower arm axis along x through (0, -0.3, 0),
// arm length L = 0.4, vertical strut 0.05 m inboard of the ball joint, tie
// rod parallel to the arm (inner point on a line parallel to the arm axis,
// outer point 0.15 m behind the ball joint), so the motion stays in the y-z
// plane and the upright only rotates about x.
kr::MacPhersonHardpoints planarStrut() {
  kr::MacPhersonHardpoints hp;
  hp.spindle = {0.0, -0.8, 0.05};
  hp.lca_f = {0.2, -0.3, 0.0};
  hp.lca_b = {-0.2, -0.3, 0.0};
  hp.lca_u = {0.0, -0.7, 0.0};
  hp.strut_u = {0.0, -0.65, 0.1};
  hp.strut_c = {0.0, -0.65, 0.6};
  hp.tierod_c = {-0.15, -0.3, 0.0};
  hp.tierod_u = {-0.15, -0.7, 0.0};
  return hp;
}

// Right-hand parallel equal-length double wishbone (arms along y, length
// L = 0.4, chassis axes along x), vertical kingpin, steering arm a = 0.15 m
// behind the kingpin, tie rod parallel and equal to the arms.
constexpr double kArm = 0.4, kSteerArm = 0.15;
kr::DoubleWishboneHardpoints parallelWishbone() {
  kr::DoubleWishboneHardpoints hp;
  hp.spindle = {0.0, -0.8, 0.15};
  hp.lca_f = {0.2, -0.3, 0.0};
  hp.lca_b = {-0.2, -0.3, 0.0};
  hp.lca_u = {0.0, -0.7, 0.0};
  hp.uca_f = {0.2, -0.3, 0.3};
  hp.uca_b = {-0.2, -0.3, 0.3};
  hp.uca_u = {0.0, -0.7, 0.3};
  hp.tierod_c = {-kSteerArm, -0.3, 0.1};
  hp.tierod_u = {-kSteerArm, -0.7, 0.1};
  return hp;
}

// Solid axle (wheel centres at y = -+0.75): three parallel trailing links of
// length 0.5 (two lower at y = -+0.5, one upper central) and a lateral
// Panhard rod of length 0.7.
constexpr double kTrailing = 0.5, kPanhard = 0.7, kAxleTrack = 1.5;
kr::SolidAxleHardpoints panhardAxle() {
  kr::SolidAxleHardpoints hp;
  hp.spindle_right = {0.0, -0.75, 0.0};
  hp.spindle_left = {0.0, 0.75, 0.0};
  hp.links = {{"lower_right", {kTrailing, -0.5, -0.1}, {0.0, -0.5, -0.1}},
              {"lower_left", {kTrailing, 0.5, -0.1}, {0.0, 0.5, -0.1}},
              {"upper", {kTrailing, 0.0, 0.15}, {0.0, 0.0, 0.15}},
              {"panhard_rod", {0.0, -0.3 + kPanhard, 0.05}, {0.0, -0.3, 0.05}}};
  return hp;
}

Vec3 vec(const nlohmann::json& j) { return {j.at(0).get<double>(), j.at(1).get<double>(), j.at(2).get<double>()}; }

nlohmann::json e90() {
  const std::string path = std::string(VDYN_TEST_DATA_DIR) + "/bmw_e90_hardpoints.json";
  std::ifstream in(path);
  if (!in) throw std::runtime_error(path + ": not found");
  return nlohmann::json::parse(in);
}

kr::MacPhersonHardpoints e90Front() {
  const nlohmann::json f = e90().at("front");
  const nlohmann::json& h = f.at("hardpoints_m");
  kr::MacPhersonHardpoints hp;
  hp.spindle = vec(h.at("SPINDLE"));
  hp.lca_f = vec(h.at("LCA_F"));
  hp.lca_b = vec(h.at("LCA_B"));
  hp.lca_u = vec(h.at("LCA_U"));
  hp.strut_c = vec(h.at(f.at("strut").at("chassis_point").get<std::string>()));
  hp.strut_u = vec(h.at(f.at("strut").at("upright_point").get<std::string>()));
  hp.tierod_c = vec(h.at("TIEROD_C"));
  hp.tierod_u = vec(h.at("TIEROD_U"));
  hp.camber_rad = f.at("static_camber_rad").get<double>();
  hp.toe_in_rad = f.at("static_toe_in_rad").get<double>();
  return hp;
}

kr::DoubleWishboneHardpoints e90Rear() {
  const nlohmann::json r = e90().at("rear");
  const nlohmann::json& h = r.at("hardpoints_m");
  kr::DoubleWishboneHardpoints hp;
  hp.spindle = vec(h.at("SPINDLE"));
  hp.uca_f = vec(h.at("UCA_F"));
  hp.uca_b = vec(h.at("UCA_B"));
  hp.uca_u = vec(h.at("UCA_U"));
  hp.lca_f = vec(h.at("LCA_F"));
  hp.lca_b = vec(h.at("LCA_B"));
  hp.lca_u = vec(h.at("LCA_U"));
  hp.tierod_c = vec(h.at("TIEROD_C"));
  hp.tierod_u = vec(h.at("TIEROD_U"));
  hp.camber_rad = r.at("static_camber_rad").get<double>();
  hp.toe_in_rad = r.at("static_toe_in_rad").get<double>();
  return hp;
}

}  // namespace

// Spin axis from camber and toe-in, and the angles read back, on both sides.
TEST(KinematicsReference, SpinAxisConventions) {
  const double gamma = 0.03, toe = 0.01;
  for (double side : {-1.0, 1.0}) {
    const Vec3 s = kr::spinAxisOutward(gamma, toe, side);
    EXPECT_NEAR(s[0] * s[0] + s[1] * s[1] + s[2] * s[2], 1.0, 1e-15);
    EXPECT_LT(s[2], 0.0);             // top outward: the outer axle end lower
    EXPECT_GT(s[0], 0.0);             // toe-in: the outer axle end forward
    EXPECT_GT(side * s[1], 0.0);      // outward
  }
  // The design pose reads the static angles back; the right wheel's steer is
  // its toe-in, the left's minus its toe-in.
  kr::DoubleWishboneHardpoints hp = parallelWishbone();
  hp.camber_rad = gamma, hp.toe_in_rad = toe;
  const kr::WheelKinematics r = kr::doubleWishboneKinematics(hp, 0.0);
  const kr::WheelKinematics l = kr::doubleWishboneKinematics(kr::mirrored(hp), 0.0);
  EXPECT_NEAR(r.camber_rad, gamma, 1e-15);
  EXPECT_NEAR(r.toe_in_rad, toe, 1e-15);
  EXPECT_NEAR(r.steer_rad, toe, 1e-15);
  EXPECT_NEAR(l.camber_rad, gamma, 1e-15);
  EXPECT_NEAR(l.toe_in_rad, toe, 1e-15);
  EXPECT_NEAR(l.steer_rad, -toe, 1e-15);
}

// Planar strut: the ball joint B on its circle about the arm axis, the strut
// line through the top mount C at the fixed distance e = 0.05 m from B, so
// its angle in the y-z plane is angle(C - B) + asin(e / |C - B|); the upright
// turns about x by that angle's change psi, which is the right wheel's
// camber; the wheel centre is B + R_x(psi) (W0 - B0).
TEST(KinematicsReference, MacPhersonPlanarClosedForm) {
  const kr::MacPhersonHardpoints hp = planarStrut();
  const double L = 0.4, e = 0.05;
  for (double beta : {-0.2, -0.1, -0.03, 0.0, 0.05, 0.12, 0.2}) {
    const double By = -0.3 - L * std::cos(beta), Bz = L * std::sin(beta);
    const double Dy = hp.strut_c[1] - By, Dz = hp.strut_c[2] - Bz;
    const double psi = std::atan2(Dz, Dy) + std::asin(e / std::hypot(Dy, Dz)) - kPi / 2;
    const double wy = hp.spindle[1] - hp.lca_u[1], wz = hp.spindle[2] - hp.lca_u[2];  // W0 - B0
    const double Wy = By + wy * std::cos(psi) - wz * std::sin(psi);
    const double Wz = Bz + wy * std::sin(psi) + wz * std::cos(psi);
    const kr::WheelKinematics k = kr::macphersonKinematics(hp, Wz - hp.spindle[2]);
    EXPECT_NEAR(k.camber_rad, psi, kTol) << "beta " << beta;
    EXPECT_NEAR(k.toe_in_rad, 0.0, kTol) << "beta " << beta;
    EXPECT_NEAR(k.track_change_m, -(Wy - hp.spindle[1]), kTol) << "beta " << beta;
    EXPECT_NEAR(k.dx_m, 0.0, kTol) << "beta " << beta;
    EXPECT_NEAR(k.wheel_centre_m[2], Wz, kTol);
    EXPECT_LT(k.loop_residual, kTol);
  }
}

// Parallel equal-length wishbones: the upright translates; no camber or toe
// change, the track change is -L (1 - cos beta) with sin beta = z / L.
TEST(KinematicsReference, DoubleWishboneParallelClosedForm) {
  const kr::DoubleWishboneHardpoints hp = parallelWishbone();
  for (double z : {-0.08, -0.04, 0.0, 0.03, 0.08}) {
    const kr::WheelKinematics k = kr::doubleWishboneKinematics(hp, z);
    const double beta = std::asin(z / kArm);
    EXPECT_NEAR(k.camber_rad, 0.0, kTol) << "z " << z;
    EXPECT_NEAR(k.toe_in_rad, 0.0, kTol) << "z " << z;
    EXPECT_NEAR(k.track_change_m, -kArm * (1.0 - std::cos(beta)), kTol) << "z " << z;
    EXPECT_NEAR(k.dx_m, 0.0, kTol);
    EXPECT_NEAR(k.dz_m, z, kTol);
    EXPECT_LT(k.loop_residual, kTol);
  }
}

// Vertical kingpin, rack travel s at zero wheel travel: the upright turns
// about the kingpin by delta with s = sqrt(Lt^2 - a^2 (1 - cos delta)^2) - Lt
// - a sin delta on the right, s = Lt - a sin delta - sqrt(...) on the left;
// d delta / d s is the inverse of ds / d delta.
TEST(KinematicsReference, RackVerticalKingpinClosedForm) {
  const kr::DoubleWishboneHardpoints right = parallelWishbone();
  const kr::DoubleWishboneHardpoints left = kr::mirrored(right);
  const double a = kSteerArm, Lt = kArm;
  for (double delta : {-0.5, -0.2, 0.0, 0.1, 0.35, 0.5}) {
    const double root = std::sqrt(Lt * Lt - std::pow(a * (1.0 - std::cos(delta)), 2));
    const double droot = -a * a * (1.0 - std::cos(delta)) * std::sin(delta) / root;
    const double s_right = root - Lt - a * std::sin(delta);
    const double s_left = Lt - a * std::sin(delta) - root;
    const kr::WheelKinematics r = kr::doubleWishboneKinematics(right, 0.0, s_right);
    const kr::WheelKinematics l = kr::doubleWishboneKinematics(left, 0.0, s_left);
    EXPECT_NEAR(r.steer_rad, delta, kTol) << "delta " << delta;
    EXPECT_NEAR(l.steer_rad, delta, kTol) << "delta " << delta;
    EXPECT_NEAR(r.camber_rad, 0.0, kTol);
    EXPECT_NEAR(r.dsteer_drack_rad_per_m, 1.0 / (droot - a * std::cos(delta)), 1e-10);
    EXPECT_NEAR(l.dsteer_drack_rad_per_m, 1.0 / (-droot - a * std::cos(delta)), 1e-10);
  }
}

// Knuckle steering (vdyn's (A.1)) on the vertical kingpin: the wheel centre
// turns about the kingpin by the steer angle, camber stays zero.
TEST(KinematicsReference, KnuckleSteerVerticalKingpinClosedForm) {
  const kr::DoubleWishboneHardpoints hp = parallelWishbone();
  const double ky = hp.lca_u[1], wy = hp.spindle[1] - ky;  // kingpin at x = 0, y = ky
  for (double delta : {-0.4, -0.05, 0.0, 0.2, 0.4}) {
    const kr::WheelKinematics k = kr::doubleWishboneKinematicsKnuckleSteer(hp, 0.0, delta);
    EXPECT_NEAR(k.steer_rad, delta, kTol);
    EXPECT_NEAR(k.camber_rad, 0.0, kTol);
    EXPECT_NEAR(k.wheel_centre_m[0], -wy * std::sin(delta), kTol);
    EXPECT_NEAR(k.wheel_centre_m[1], ky + wy * std::cos(delta), kTol);
    EXPECT_NEAR(k.dz_m, 0.0, kTol);
    EXPECT_LT(k.loop_residual, kTol);
  }
}

// Three parallel equal trailing links and a lateral Panhard rod: in heave the
// axle translates by (dx, dy, z) with dx = Lp dy / L and
// (1 + Lp^2 / L^2) dy^2 - 2 Lp dy + z^2 = 0 (the small root).
TEST(KinematicsReference, SolidAxlePanhardHeaveClosedForm) {
  const kr::SolidAxleHardpoints hp = panhardAxle();
  const double L = kTrailing, Lp = kPanhard;
  for (double z : {-0.08, -0.03, 0.0, 0.05, 0.08}) {
    const double A = 1.0 + Lp * Lp / (L * L);
    const double dy = (2.0 * Lp - std::sqrt(4.0 * Lp * Lp - 4.0 * A * z * z)) / (2.0 * A);
    const double dx = Lp * dy / L;
    const kr::AxleKinematics k = kr::solidAxleKinematics(hp, z, z);
    for (const kr::WheelKinematics* w : {&k.right, &k.left}) {
      EXPECT_NEAR(w->dx_m, dx, kTol) << "z " << z;
      EXPECT_NEAR(w->dz_m, z, kTol);
      EXPECT_NEAR(w->camber_rad, 0.0, kTol);
      EXPECT_NEAR(w->toe_in_rad, 0.0, kTol);
      EXPECT_LT(w->loop_residual, kTol);
    }
    EXPECT_NEAR(k.right.track_change_m, -dy, kTol) << "z " << z;  // the axle moves to +y
    EXPECT_NEAR(k.left.track_change_m, dy, kTol) << "z " << z;
    EXPECT_NEAR(k.roll_rad, 0.0, kTol);
  }
}

// Opposite travel: the rigid axle's wheel-centre line keeps its length T, so
// camber_right = asin((z_left - z_right) / T) = -camber_left = roll, whatever
// the axle's roll steer.
TEST(KinematicsReference, SolidAxleRollCamberClosedForm) {
  const kr::SolidAxleHardpoints hp = panhardAxle();
  for (double h : {-0.06, -0.02, 0.03, 0.06}) {
    const kr::AxleKinematics k = kr::solidAxleKinematics(hp, -h, h);
    const double gamma = std::asin(2.0 * h / kAxleTrack);
    EXPECT_NEAR(k.right.camber_rad, gamma, kTol) << "h " << h;
    EXPECT_NEAR(k.left.camber_rad, -gamma, kTol) << "h " << h;
    EXPECT_NEAR(k.roll_rad, gamma, kTol) << "h " << h;
    EXPECT_LT(k.right.loop_residual, kTol);
  }
  kr::SolidAxleHardpoints three = hp;
  three.links.pop_back();
  EXPECT_THROW(kr::solidAxleKinematics(three, 0.0, 0.0), std::invalid_argument);
}

// The analytic loop Jacobians against central differences on the same
// manifold update, at poses away from design.
TEST(KinematicsReference, JacobiansMatchCentralDifferences) {
  EXPECT_LT(kr::macphersonJacobianError(e90Front(), 0.05, 0.01), 1e-8);
  EXPECT_LT(kr::macphersonJacobianError(e90Front(), -0.07, -0.02), 1e-8);
  EXPECT_LT(kr::doubleWishboneJacobianError(e90Rear(), -0.04, 0.0), 1e-8);
  EXPECT_LT(kr::doubleWishboneJacobianError(parallelWishbone(), 0.03, 0.05), 1e-8);
  EXPECT_LT(kr::doubleWishboneKnuckleSteerJacobianError(e90Rear(), 0.05, 0.3), 1e-8);
  kr::SolidAxleHardpoints hp = panhardAxle();
  EXPECT_LT(kr::solidAxleJacobianError(hp, 0.03, -0.02), 1e-8);
}

// Symmetric rack: equal (zero) left and right angles at zero rack travel,
// mirror symmetry delta_left(s) = -delta_right(-s), and the overall ratio by
// implicit differentiation against central differences over the pinion.
TEST(KinematicsReference, RackSymmetryAndOverallRatio) {
  const kr::MacPhersonHardpoints hp = e90Front();
  const double c = -0.1;  // m/rad: tie rods behind the axle, a left turn moves the rack right
  const kr::RackSteer zero = kr::rackSteer(hp, 0.0, c);
  EXPECT_NEAR(zero.steer_left_rad, zero.steer_right_rad, 1e-15);
  EXPECT_NEAR(zero.steer_right_rad, 0.0, 1e-15);
  for (double pinion : {0.2, 0.6, 1.0}) {
    const kr::RackSteer p = kr::rackSteer(hp, pinion, c);
    const kr::RackSteer m = kr::rackSteer(hp, -pinion, c);
    EXPECT_NEAR(p.steer_left_rad, -m.steer_right_rad, kTol);
    EXPECT_NEAR(p.steer_right_rad, -m.steer_left_rad, kTol);
    EXPECT_GT(p.steer_mean_rad, 0.0);  // a positive pinion angle turns left
    const double h = 1e-5;
    const double dmean = (kr::rackSteer(hp, pinion + h, c).steer_mean_rad -
                          kr::rackSteer(hp, pinion - h, c).steer_mean_rad) / (2.0 * h);
    EXPECT_NEAR(p.overall_ratio * dmean, 1.0, 1e-7) << "pinion " << pinion;
  }
  EXPECT_THROW(kr::rackSteer(hp, 0.1, 0.0), std::invalid_argument);
  EXPECT_THROW(kr::rackSteer(kr::mirrored(hp), 0.1, c), std::invalid_argument);
}

// The E90's front strut and rear double wishbone over +-80 mm of wheel travel
// (tests/data/bmw_e90_hardpoints.json, docs/bmw_e90.md): printed, loops closed,
// static angles at design, and the steering over the pinion's range.
TEST(KinematicsReference, E90Tables) {
  const kr::MacPhersonHardpoints front = e90Front();
  const kr::DoubleWishboneHardpoints rear = e90Rear();
  const double deg = 180.0 / kPi;
  std::printf("E90 front MacPherson strut, right wheel (camber + top out, toe + in, track change + out, dx + forward)\n");
  std::printf("  z_mm   camber_deg   toe_in_deg   track_change_mm   dx_mm   iterations  residual_m\n");
  for (int zmm = -80; zmm <= 80; zmm += 20) {
    const kr::WheelKinematics k = kr::macphersonKinematics(front, zmm * 1e-3);
    std::printf("  %4d  %11.6f  %11.6f  %15.6f  %9.6f  %4d  %.1e\n", zmm, k.camber_rad * deg, k.toe_in_rad * deg,
                k.track_change_m * 1e3, k.dx_m * 1e3, k.newton_iterations, k.loop_residual);
    EXPECT_LT(k.loop_residual, kTol);
    EXPECT_NEAR(k.dz_m, zmm * 1e-3, kTol);
    if (zmm == 0) {
      EXPECT_NEAR(k.camber_rad, -2.0 / deg, 1e-15);
      EXPECT_NEAR(k.toe_in_rad, 0.0, 1e-15);
    }
  }
  std::printf("E90 rear double wishbone, right wheel\n");
  std::printf("  z_mm   camber_deg   toe_in_deg   track_change_mm   dx_mm\n");
  for (int zmm = -80; zmm <= 80; zmm += 20) {
    const kr::WheelKinematics k = kr::doubleWishboneKinematics(rear, zmm * 1e-3);
    std::printf("  %4d  %11.6f  %11.6f  %15.6f  %9.6f\n", zmm, k.camber_rad * deg, k.toe_in_rad * deg,
                k.track_change_m * 1e3, k.dx_m * 1e3);
    EXPECT_LT(k.loop_residual, kTol);
  }
  const double c = -0.1;  // Chrono: pinion radius 0.1 m, max pinion angle 64 deg
  std::printf("E90 rack and pinion, c = %.3f m/rad (steer + left)\n", c);
  std::printf("  pinion_deg  rack_mm   steer_left_deg  steer_right_deg  mean_deg  overall_ratio\n");
  for (int pdeg = -64; pdeg <= 64; pdeg += 16) {
    const kr::RackSteer r = kr::rackSteer(front, pdeg / deg, c);
    std::printf("  %9d  %8.3f  %14.6f  %15.6f  %8.6f  %12.6f\n", pdeg, r.rack_travel_m * 1e3, r.steer_left_rad * deg,
                r.steer_right_rad * deg, r.steer_mean_rad * deg, r.overall_ratio);
    EXPECT_LT(r.left.loop_residual, kTol);
    EXPECT_LT(r.right.loop_residual, kTol);
  }
}

// The E90 data file's totals from its bodies (docs/bmw_e90.md, "Vehicle
// totals"): each body where Chrono places it at design, both sides; the axle
// loads by the moment balance about the contact points below the wheel centres.
TEST(KinematicsReference, E90TotalsFromItsBodies) {
  const nlohmann::json d = e90();
  double m = 0.0, mx = 0.0, my = 0.0, mz = 0.0;
  auto add = [&](double mass, const Vec3& p, bool both_sides) {
    for (int k = 0; k < (both_sides ? 2 : 1); ++k) {
      const double side = k == 0 ? 1.0 : -1.0;  // the second is the mirror image
      m += mass, mx += mass * p[0], my += mass * side * p[1], mz += mass * p[2];
    }
  };
  add(d.at("chassis").at("mass_kg").get<double>(), vec(d.at("chassis").at("cm_m")), false);
  for (const char* axle : {"front", "rear"}) {
    const nlohmann::json& a = d.at(axle);
    const nlohmann::json& h = a.at("hardpoints_m");
    for (const auto& [name, body] : a.at("bodies").items()) {
      if (!body.is_object()) continue;
      const std::string at = body.at("at").get<std::string>();
      Vec3 p{};
      if (at.rfind("midpoint ", 0) == 0) {
        const std::string pair = at.substr(9);
        const Vec3 p1 = vec(h.at(pair.substr(0, pair.find(' ')))), p2 = vec(h.at(pair.substr(pair.find(' ') + 1)));
        p = {0.5 * (p1[0] + p2[0]), 0.5 * (p1[1] + p2[1]), 0.5 * (p1[2] + p2[2])};
      } else {
        p = vec(h.at(at));
      }
      add(body.at("mass_kg").get<double>(), p, true);
    }
    const Vec3 spindle = vec(h.at("SPINDLE"));
    add(a.at("wheel").at("mass_kg").get<double>(), spindle, true);
    add(a.at("tire_tmeasy").at("mass_kg").get<double>(), spindle, true);
    const nlohmann::json& arb = a.at("anti_roll_bar");
    const Vec3 loc = vec(arb.at("location_m"));
    add(arb.at("arm_mass_kg").get<double>(), {loc[0], -0.5 * arb.at("arm_reach_m").get<double>(), loc[2]}, true);
  }
  add(d.at("steering").at("rack_mass_kg").get<double>(), vec(d.at("steering").at("location_m")), false);
  const nlohmann::json& t = d.at("totals_tmeasy");
  EXPECT_NEAR(m, t.at("mass_kg").get<double>(), 1e-9);
  const Vec3 cm{mx / m, my / m, mz / m}, cm_file = vec(t.at("cm_m"));
  for (int i = 0; i < 3; ++i) EXPECT_NEAR(cm[i], cm_file[i], 1e-11);
  const double g = t.at("gravity_m_per_s2").get<double>(), L = d.at("wheelbase_m").get<double>();
  const double x_front = vec(d.at("front").at("hardpoints_m").at("SPINDLE"))[0];
  const double x_rear = vec(d.at("rear").at("hardpoints_m").at("SPINDLE"))[0];
  EXPECT_NEAR(x_front - x_rear, L, 1e-12);
  const double front = m * g * (cm[0] - x_rear) / L, rear = m * g * (x_front - cm[0]) / L;
  EXPECT_NEAR((front + rear) / (m * g), 1.0, 1e-12);
  EXPECT_NEAR(front, t.at("front_axle_load_N").get<double>(), 1e-6);
  EXPECT_NEAR(rear, t.at("rear_axle_load_N").get<double>(), 1e-6);
  std::printf("E90 (TMeasy): mass %.6f kg, c.m. (%.6f, %.6f, %.6f) m, axle loads front %.4f N, rear %.4f N\n", m, cm[0],
              cm[1], cm[2], front, rear);
}
