// Tire force laws on their own (ContactKinematics in, TireForces out): slopes at
// zero slip, saturation, Gim = Fiala in pure lateral slip, sign of the forces,
// off-ground and low-speed behaviour (finite, continuous), the normal force, the
// error messages, and the linear tire. Conventions (tire_model.h): forces in the
// contact frame C on the wheel, opposing the slip velocity (Vx - Omega Re, Vy);
// Re = R1 - delta / 3.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <functional>
#include <limits>
#include <memory>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "test_util.h"

#include "vdyn/core/params.h"
#include "vdyn/tire/tire_model.h"

using namespace vdyn;
using vdyn::test::errorOf;

namespace {

const std::vector<std::string> kSaturating = {"gim", "fiala"};
const std::vector<std::string> kAll = {"gim", "fiala", "linear"};
const std::vector<double> kLoads_N = {2000.0, 4000.0, 6000.0};

/// Tire kind `type` with brush parameters p ("linear": their linearisation),
/// built from its keys as the registry's factory builds it.
std::shared_ptr<const TireModel> makeModel(const std::string& type, const BrushTireParams& p) {
  const Json keys = type == "linear" ? LinearTireParams::linearised(p).toJson() : p.toJson();
  return makeTireModel(type, ParamReader::fromJson(keys, "tire"));
}

/// Contact at normal load Fz (deflection Fz / Kz, zero deflection rate), forward
/// speed vx, lateral speed vy and rolling speed vr = Omega Re (spin = vr / Re).
ContactKinematics contact(const TireModel& m, double Fz, double vx, double vy, double vr) {
  ContactKinematics k;
  k.deflection_m = Fz / m.vertical().radial_stiffness_N_per_m;
  k.deflection_rate_m_s = 0;
  k.vx_m_s = vx;
  k.vy_m_s = vy;
  k.spin_rad_s = vr / m.calcRollingRadius(k.deflection_m);
  return k;
}

/// Longitudinal slip velocity Vx - Omega Re, computed the way the model does.
double slipVelocity(const TireModel& m, const ContactKinematics& k) {
  return k.vx_m_s - k.spin_rad_s * m.calcRollingRadius(k.deflection_m);
}

/// All outputs of a TireForces, for finiteness and continuity checks.
std::vector<double> outputs(const TireForces& f) {
  return {f.fx_N, f.fy_N, f.fz_N, f.my_N_m, f.mz_N_m, f.slip_ratio, f.slip_angle_rad, f.mu};
}

/// The force and moment outputs (N, N m) compared in the continuity test.
std::vector<double> loads(const TireForces& f) { return {f.fx_N, f.fy_N, f.fz_N, f.my_N_m, f.mz_N_m}; }

}  // namespace

// --- Slopes at zero slip -------------------------------------------------------
// Central difference with step h in the slip ratio kappa (Omega Re = vx (1 + kappa))
// and in tan(alpha) (vy = vx tan(alpha)), around free rolling at vx = 10 m/s.
// Truncation error of the brush models (Gim, Fiala lateral): near zero slip
// F = C s (1 - C |s| / (3 mu_max Fz)) + O(s^3), whose s|s| term is odd, so the
// central difference keeps it: relative error h C / (3 mu_max Fz); Gim's driving
// slip S_s = kappa / (1 + kappa) adds h / 2. Worst case here (Fz = 2000 N, C_s =
// 8e4, mu_max = 0.8): h (16.7 + 0.5) = 1.7e-7 at h = 1e-8. Round-off: the slip
// velocity h vx carries an absolute error of a few eps vx, i.e. a relative error
// of a few eps / h = 1e-8 in the quotient. Both are well below the 1e-6 asked for.
TEST(TireSlope, ZeroSlipSlopesEqualStiffnesses) {
  const BrushTireParams p;
  const double h = 1e-8, vx = 10.0;
  for (const std::string& name : kAll) {
    const auto m = makeModel(name, p);
    for (double Fz : kLoads_N) {
      SCOPED_TRACE(name + " at Fz = " + std::to_string(Fz));
      const double fxPlus = m->calcForces(contact(*m, Fz, vx, 0, vx * (1 + h))).fx_N;
      const double fxMinus = m->calcForces(contact(*m, Fz, vx, 0, vx * (1 - h))).fx_N;
      const double dFx_dkappa = (fxPlus - fxMinus) / (2 * h);
      EXPECT_NEAR(dFx_dkappa, p.longitudinal_stiffness_N, 1e-6 * p.longitudinal_stiffness_N);

      const double fyPlus = m->calcForces(contact(*m, Fz, vx, vx * h, vx)).fy_N;
      const double fyMinus = m->calcForces(contact(*m, Fz, vx, -vx * h, vx)).fy_N;
      // Fy opposes Vy: dFy/d(tan alpha) = -C_a.
      const double dFy_dtan = (fyPlus - fyMinus) / (2 * h);
      EXPECT_NEAR(dFy_dtan, -p.cornering_stiffness_N_per_rad, 1e-6 * p.cornering_stiffness_N_per_rad);

      // Free rolling without side slip: no tangential force (the rolling speed
      // Omega Re reproduces vx to a few ulp, so Fx is at most C_s * few eps).
      const TireForces f0 = m->calcForces(contact(*m, Fz, vx, 0, vx));
      EXPECT_NEAR(f0.fx_N, 0.0, 1e-9);
      EXPECT_EQ(f0.fy_N, 0.0);
    }
  }
}

// --- Saturation ------------------------------------------------------------------
// At comprehensive slip S >= 1 mu = mu_min, and for Gim the adhesion fraction l_n is
// 0 once |(C_s S_s, C_a S_a)| >= 3 mu Fz (here >= 5.3e4 N against 3 mu Fz <= 1.44e4 N),
// so |F| = mu Fz * |unit vector|: a few ulp, hence 1e-12 relative. Gim's driving slip
// S_s = (Omega Re - Vx) / (Omega Re) stays below 1 while Vx > 0 (2/3 at Omega Re = 3 Vx,
// so mu = 0.8 - 0.2 * 2/3 there): fully sliding, but at mu(S) rather than mu_min.
TEST(TireSaturation, GimResultantIsMuFzAtLargeSlip) {
  const BrushTireParams p;
  const auto m = makeModel("gim", p);
  const double vx = 10.0;
  struct Case {
    const char* what;
    double vx, vy, vr;
    double mu;  ///< expected friction coefficient
  };
  const double muDriving = p.mu_max - (p.mu_max - p.mu_min) * (2.0 / 3.0);
  const std::vector<Case> cases = {
      {"locked wheel", vx, 0, 0, p.mu_min},
      {"locked wheel reversing", -vx, 0, 0, p.mu_min},
      {"tan(alpha) = 5", vx, 5 * vx, vx, p.mu_min},
      {"tan(alpha) = -5", vx, -5 * vx, vx, p.mu_min},
      {"reversing, tan(alpha) = 5", -vx, 5 * vx, -vx, p.mu_min},
      {"locked, tan(alpha) = 5", vx, 5 * vx, 0, p.mu_min},
      {"spinning in place", 0, 0, vx, p.mu_min},
      {"spinning at 3 vx, tan(alpha) = -5", vx, -5 * vx, 3 * vx, p.mu_min},
      {"spinning at 3 vx (S_s = 2/3)", vx, 0, 3 * vx, muDriving},
  };
  for (double Fz : kLoads_N)
    for (const Case& c : cases) {
      SCOPED_TRACE(std::string(c.what) + " at Fz = " + std::to_string(Fz));
      const ContactKinematics k = contact(*m, Fz, c.vx, c.vy, c.vr);
      const TireForces f = m->calcForces(k);
      EXPECT_NEAR(f.mu, c.mu, 1e-15);
      EXPECT_NEAR(std::hypot(f.fx_N, f.fy_N), c.mu * f.fz_N, 1e-12 * c.mu * f.fz_N);
      EXPECT_NEAR(f.fz_N, Fz, 1e-9 * Fz);
    }
}

// Fiala saturates laterally at mu_min Fz (H <= 0 once C_a |tan alpha| >= 3 mu Fz).
// Longitudinally it only approaches mu Fz: at a locked wheel (|kappa| = 1, beyond
// the critical slip mu Fz / (2 C_s) = 0.0225 at 6000 N) the published law gives
// Fx = -(mu Fz - (mu Fz)^2 / (4 C_s)) exactly (same operations: to 1e-12).
TEST(TireSaturation, FialaLateralIsMuMinFzAndLockedWheelFollowsThePublishedLaw) {
  const BrushTireParams p;
  const auto m = makeModel("fiala", p);
  const double vx = 10.0;
  for (double Fz : kLoads_N) {
    SCOPED_TRACE("Fz = " + std::to_string(Fz));
    for (double tanA : {5.0, -5.0}) {
      const TireForces f = m->calcForces(contact(*m, Fz, vx, tanA * vx, vx));
      EXPECT_EQ(f.mu, p.mu_min);
      EXPECT_NEAR(f.fy_N, -std::copysign(p.mu_min * f.fz_N, tanA), 1e-12 * p.mu_min * f.fz_N);
    }
    const TireForces f = m->calcForces(contact(*m, Fz, vx, 0, 0));
    const double muFz = p.mu_min * f.fz_N;
    EXPECT_NEAR(f.fx_N, -(muFz - muFz * muFz / (4 * p.longitudinal_stiffness_N)), 1e-12 * muFz);
    EXPECT_LT(std::abs(f.fx_N), muFz);
  }
}

// --- Gim in combined slip against docs/equations.md "Tire: Gim" -----------------------
// An independent evaluation of those formulas, written with the slip angle
// and cos/sin(theta) instead of the model's ratios: braking S_s = (Vx - Omega Re) / Vx,
// S_a = |tan alpha|; driving S_s = (Omega Re - Vx) / (Omega Re), S_a = (1 - S_s) |tan alpha|;
// mu linear in S = |(S_s, S_a)|; l_n = 1 - |(C_s S_s, C_a S_a)| / (3 mu Fz) in [0, 1].
// Only the operation order differs from the model (a few ulp): 1e-12 relative.
TEST(TireGimCombined, MatchesTheSectionEightFormulas) {
  const BrushTireParams p;
  const auto m = makeModel("gim", p);
  const double Cs = p.longitudinal_stiffness_N, Ca = p.cornering_stiffness_N_per_rad;
  struct Case {
    double vx, vy, vr;
  };
  // Adhesion and sliding share the patch (0 < l_n < 1) in the first four; the
  // others slide more or entirely.
  const std::vector<Case> cases = {{10, 0.05, 10.2}, {10, -0.08, 9.9}, {20, 0.3, 20.1}, {10, 0.02, 9.97},
                                   {10, 1.0, 12.0},  {10, 0.5, 9.0},   {10, -2.0, 15.0}, {10, 0.3, 5.0}};
  int partial = 0;
  for (double Fz : kLoads_N)
    for (const Case& c : cases) {
      SCOPED_TRACE("Fz " + std::to_string(Fz) + ", vx " + std::to_string(c.vx) + ", vy " + std::to_string(c.vy) +
                   ", Omega Re " + std::to_string(c.vr));
      const ContactKinematics k = contact(*m, Fz, c.vx, c.vy, c.vr);
      const TireForces f = m->calcForces(k);
      const double vr = k.spin_rad_s * m->calcRollingRadius(k.deflection_m);
      const bool driving = vr > c.vx;
      const double tanA = std::abs(c.vy / c.vx);
      const double Ss = driving ? (vr - c.vx) / vr : (c.vx - vr) / c.vx;
      const double Sa = driving ? (1 - Ss) * tanA : tanA;
      const double mu = p.mu_max - (p.mu_max - p.mu_min) * std::min(1.0, std::hypot(Ss, Sa));
      const double FzModel = p.vertical.radial_stiffness_N_per_m * k.deflection_m;
      const double ln = std::clamp(1 - std::hypot(Cs * Ss, Ca * Sa) / (3 * mu * FzModel), 0.0, 1.0);
      const double theta = std::atan2(Ca * Sa, Cs * Ss);
      const double sliding = 1 - 3 * ln * ln + 2 * ln * ln * ln;
      const double Fxi = Cs * Ss * ln * ln + mu * FzModel * std::cos(theta) * sliding;
      const double Feta = Ca * Sa * ln * ln + mu * FzModel * std::sin(theta) * sliding;
      const double scale = mu * FzModel;
      EXPECT_NEAR(f.mu, mu, 1e-14);
      EXPECT_NEAR(f.fx_N, driving ? Fxi : -Fxi, 1e-12 * scale);
      EXPECT_NEAR(f.fy_N, -std::copysign(Feta, c.vy), 1e-12 * scale);
      EXPECT_LE(std::hypot(f.fx_N, f.fy_N), scale * (1 + 1e-12));  // inside the friction circle
      if (ln > 0 && ln < 1) ++partial;
    }
  EXPECT_GE(partial, 8);  // the adhesion/sliding split was really exercised
}

// --- Gim = Fiala in pure lateral slip ---------------------------------------------
// With constant friction the two laws are the same polynomial in
// e = C_a |tan alpha| / (3 mu Fz): mu Fz (1 - (1 - e)^3) for e < 1, mu Fz beyond.
// The two evaluations differ only by rounding; the worst cancellation (1 - H^3 at
// the smallest e ~ 1e-3 of this sweep) costs ~eps / e ~ 1e-13 relative, so 1e-9
// relative is a comfortable bound (plus 1e-12 N where both are exactly 0).
TEST(TireGimFiala, EqualInPureLateralSlipWithConstantFriction) {
  const double vx = 10.0;
  for (double mu : {0.6, 0.8}) {
    BrushTireParams p;
    p.mu_max = p.mu_min = mu;
    const auto gim = makeModel("gim", p);
    const auto fiala = makeModel("fiala", p);
    for (double Fz : kLoads_N) {
      int sliding = 0;
      for (int i = 0; i <= 120; ++i) {
        const double alpha = -0.3 + 0.6 * i / 120.0;
        SCOPED_TRACE("mu = " + std::to_string(mu) + ", Fz = " + std::to_string(Fz) +
                     ", alpha = " + std::to_string(alpha));
        const ContactKinematics k = contact(*gim, Fz, vx, vx * std::tan(alpha), vx);
        const TireForces g = gim->calcForces(k), f = fiala->calcForces(k);
        EXPECT_NEAR(g.fy_N, f.fy_N, 1e-9 * std::abs(f.fy_N) + 1e-12);
        EXPECT_NEAR(g.mz_N_m, f.mz_N_m, 1e-9 * std::abs(f.mz_N_m) + 1e-12);
        EXPECT_NEAR(g.fx_N, 0.0, 1e-9);  // free rolling: only rounding in Omega Re
        if (std::abs(f.fy_N) == mu * f.fz_N) ++sliding;
      }
      // The sweep must reach the fully sliding range (e >= 1) at every load:
      // e = 1 at tan(alpha) = 3 mu Fz / C_a <= 0.26 < tan(0.3).
      EXPECT_GT(sliding, 0) << "Fz = " << Fz;
    }
  }
}

// --- Signs ---------------------------------------------------------------------------
// Forces oppose the slip velocity: Fx (Vx - Omega Re) <= 0, Fy Vy <= 0, strictly
// negative when that slip component is nonzero; in all four quadrants of
// (Vx - Omega Re, Vy), braking and driving, forward and reversing, at low speed.
TEST(TireSign, ForcesOpposeTheSlipVelocity) {
  const BrushTireParams p;
  for (const std::string& name : kSaturating) {
    const auto m = makeModel(name, p);
    int cases = 0;
    for (double vx : {10.0, -10.0, 0.2, -0.2, 0.0})
      for (double vr : {0.8 * vx, 1.2 * vx, -vx, 0.0, 0.3, -0.3, 12.0, -12.0, vx})
        for (double vy : {1.0, -1.0, 0.05, -0.05, 0.0}) {
          const ContactKinematics k = contact(*m, 4000.0, vx, vy, vr);
          const TireForces f = m->calcForces(k);
          const double vsx = slipVelocity(*m, k);
          SCOPED_TRACE(name + ": vx = " + std::to_string(vx) + ", Omega Re = " + std::to_string(vr) +
                       ", vy = " + std::to_string(vy) + ", Vx - Omega Re = " + std::to_string(vsx));
          if (vsx != 0) {
            EXPECT_LT(f.fx_N * vsx, 0.0);
            ++cases;
          } else {
            EXPECT_EQ(f.fx_N, 0.0);
          }
          if (vy != 0) EXPECT_LT(f.fy_N * vy, 0.0);
          else EXPECT_EQ(f.fy_N, 0.0);
        }
    EXPECT_GT(cases, 150);  // the slip-velocity branch was really exercised
  }
}

// Mirror symmetry. Reflecting y (Vy -> -Vy) flips Fy and Mz and keeps Fx; reversing
// (Vx -> -Vx, Omega -> -Omega, so the slip velocity flips too) flips Fx and keeps Fy:
// driving backwards at Omega Re = -12 m/s, Vx = -10 m/s must give the force of driving
// forwards, mirrored. Both mirrors take the same floating-point path (only signs and
// absolute values change), so the comparison is to 4 ulp.
TEST(TireSign, MirrorSymmetry) {
  const BrushTireParams p;
  for (const std::string& name : kAll) {
    const auto m = makeModel(name, p);
    for (double vx : {10.0, 1.0, 0.3, 0.0})
      for (double vr : {0.0, 0.5 * vx, vx, 1.5 * vx, 12.0, -3.0, 0.2})
        for (double vy : {0.5, 2.0, -0.1, 0.0}) {
          SCOPED_TRACE(name + ": vx = " + std::to_string(vx) + ", Omega Re = " + std::to_string(vr) +
                       ", vy = " + std::to_string(vy));
          const TireForces f = m->calcForces(contact(*m, 4000.0, vx, vy, vr));
          const TireForces fy = m->calcForces(contact(*m, 4000.0, vx, -vy, vr));
          const TireForces fx = m->calcForces(contact(*m, 4000.0, -vx, vy, -vr));
          EXPECT_DOUBLE_EQ(fy.fx_N, f.fx_N);
          EXPECT_DOUBLE_EQ(fy.fy_N, -f.fy_N);
          EXPECT_DOUBLE_EQ(fy.mz_N_m, -f.mz_N_m);
          EXPECT_DOUBLE_EQ(fx.fx_N, -f.fx_N);
          EXPECT_DOUBLE_EQ(fx.fy_N, f.fy_N);
          EXPECT_DOUBLE_EQ(fx.fz_N, f.fz_N);
        }
  }
}

// --- Off the ground, extreme kinematics ------------------------------------------------
TEST(TireContact, ZeroForceOffTheGround) {
  const BrushTireParams p;
  for (const std::string& name : kAll) {
    const auto m = makeModel(name, p);
    for (double d : {0.0, -0.0, -1e-12, -0.05, -1e300})
      for (double rate : {0.0, 100.0, -100.0}) {
        SCOPED_TRACE(name + ": deflection " + std::to_string(d) + ", rate " + std::to_string(rate));
        const ContactKinematics k{d, rate, 12.0, -3.0, 20.0, 0.1};
        EXPECT_EQ(m->calcNormalForce(k), 0.0);
        for (double v : outputs(m->calcForces(k))) EXPECT_EQ(v, 0.0);
      }
    // In contact but pulling away faster than the spring pushes: Fz clamps to 0 and
    // the tire carries no tangential force either (Kz delta + Cz delta' = 1500 - 4000 < 0).
    const ContactKinematics k{0.01, -10.0, 12.0, -3.0, 20.0, 0.1};
    EXPECT_EQ(m->calcNormalForce(k), 0.0);
    for (double v : outputs(m->calcForces(k))) EXPECT_EQ(v, 0.0);
  }
}

// Finite but extreme inputs: speeds and deflection rates up to 1e300, deflections
// from 1e-300 m up to 3 R1 (where Re = 0). No output may be NaN. (Deflection is
// capped at 3 R1: beyond it Re = R1 - delta / 3 < 0 and is not a tire any more.)
// Up to 1e100 every output must also be finite.
TEST(TireContact, NoNaNWithExtremeFiniteKinematics) {
  const BrushTireParams p;
  const double R1 = p.vertical.unloaded_radius_m;
  const std::vector<double> v = {-1e300, -1e100, -1e10, -1, -1e-300, 0, 1e-300, 1e-9, 1, 1e10, 1e100, 1e300};
  for (const std::string& name : kAll) {
    const auto m = makeModel(name, p);
    long n = 0, nan = 0, nonFiniteModerate = 0;
    for (double d : {1e-300, 1e-12, 1e-3, 0.1, R1, 3 * R1})
      for (double rate : {-1e300, -1.0, 0.0, 1.0, 1e100, 1e300})
        for (double vx : v)
          for (double vy : v)
            for (double w : v)
              for (double camber : {-1e10, 0.0, 0.3}) {
                const TireForces f = m->calcForces({d, rate, vx, vy, w, camber});
                const bool moderate = std::abs(rate) <= 1e100 && std::abs(vx) <= 1e100 &&
                                      std::abs(vy) <= 1e100 && std::abs(w) <= 1e100;
                ++n;
                for (double o : outputs(f)) {
                  if (std::isnan(o)) {
                    if (nan++ < 3)
                      ADD_FAILURE() << name << " NaN at deflection " << d << ", rate " << rate << ", vx " << vx
                                    << ", vy " << vy << ", spin " << w << ", camber " << camber;
                  } else if (moderate && !std::isfinite(o)) {
                    if (nonFiniteModerate++ < 3)
                      ADD_FAILURE() << name << " non-finite at deflection " << d << ", rate " << rate << ", vx "
                                    << vx << ", vy " << vy << ", spin " << w;
                  }
                }
              }
    EXPECT_EQ(nan, 0) << name << " over " << n << " cases";
    EXPECT_EQ(nonFiniteModerate, 0) << name << " over " << n << " cases";
  }
}

// --- Finite and continuous near standstill -----------------------------------------------
// Grid over forward speed (through 0 and the low-speed threshold 0.5 m/s, reversing),
// rolling speed Omega Re (locked, spinning in place, = vx, = -vx) and lateral speed
// (through 0). Every output is finite, and a step of 1e-9 m/s in vx, vy or Omega Re
// (forward and backward, so crossing vx = 0, Omega Re = vx, Omega Re = -vx and vy = 0
// from the grid points sitting on them) changes no force by more than 1e-3 N (N m).
// Bound: slips are velocities over a denominator >= v_eps = 0.5 m/s, so
// |dF/dv| <= max(C_s, C_a) / v_eps (1 + O(mu Fz)) ~ 1.6e5 N s/m and a 1e-9 m/s step moves
// a force by ~1.6e-4 N. A jump (a sign or branch discontinuity) would be of order
// mu Fz ~ 1e3 N.
TEST(TireContinuity, FiniteAndContinuousThroughStandstill) {
  const BrushTireParams p;
  const double step = 1e-9;
  const std::vector<double> speeds = {-10, -1, -0.5, -0.3, -0.1, -1e-6, 0, 1e-6, 0.1, 0.3, 0.5, 1, 10};
  const std::vector<double> lateral = {-3, -0.5, -0.1, -1e-6, 0, 1e-6, 0.1, 0.5, 3};
  for (const std::string& name : kAll) {
    const auto m = makeModel(name, p);
    double worst = 0;
    std::string worstAt;
    for (double Fz : {500.0, 4000.0})
      for (double vx : speeds) {
        std::vector<double> rolling = speeds;
        rolling.push_back(-vx);  // equal magnitude, opposite sign: Gim's braking/driving switch
        for (double vr : rolling)
          for (double vy : lateral) {
            const ContactKinematics k = contact(*m, Fz, vx, vy, vr);
            const std::vector<double> f0 = loads(m->calcForces(k));
            for (double o : outputs(m->calcForces(k))) ASSERT_TRUE(std::isfinite(o)) << name;
            const double Re = m->calcRollingRadius(k.deflection_m);
            for (int dir = 0; dir < 3; ++dir)
              for (double s : {step, -step}) {
                ContactKinematics kk = k;
                if (dir == 0) kk.vx_m_s += s;
                if (dir == 1) kk.vy_m_s += s;
                if (dir == 2) kk.spin_rad_s += s / Re;
                const std::vector<double> f1 = loads(m->calcForces(kk));
                for (std::size_t i = 0; i < f0.size(); ++i) {
                  ASSERT_TRUE(std::isfinite(f1[i]));
                  const double diff = std::abs(f1[i] - f0[i]);
                  if (diff > worst) {
                    worst = diff;
                    worstAt = "output " + std::to_string(i) + " at Fz " + std::to_string(Fz) + ", vx " +
                              std::to_string(vx) + ", Omega Re " + std::to_string(vr) + ", vy " +
                              std::to_string(vy) + ", step in " + "xyw"[dir];
                  }
                }
              }
          }
      }
    // The linear tire does not saturate: F = C s with s up to |Omega Re - Vx| / v_eps = 20 on
    // this grid, so |dF/dv| <= C_s (|Omega Re| + |Vx|) / v_eps^2 = 8e4 * 20 / 0.25 = 6.4e6 N s/m,
    // i.e. 6.4e-3 N per step; it gets 1e-2 N, still far below any jump.
    const double bound = name == "linear" ? 1e-2 : 1e-3;
    EXPECT_LT(worst, bound) << name << ": largest change " << worst << " N for a 1e-9 m/s step, " << worstAt;
    std::printf("[   INFO   ] %s: largest change for a 1e-9 m/s step %.3g (%s)\n", name.c_str(), worst,
                worstAt.c_str());
  }
}

// --- Normal force and energy ------------------------------------------------------------
TEST(TireNormal, SpringDamperClampedAtZeroAndItsEnergy) {
  const BrushTireParams p;
  const auto m = makeModel("gim", p);
  const double Kz = p.vertical.radial_stiffness_N_per_m, Cz = p.vertical.radial_damping_N_s_per_m;
  for (double d : {1e-6, 0.01, 0.02})
    for (double rate : {-1.0, -0.2, 0.0, 0.3, 2.0}) {
      ContactKinematics k;
      k.deflection_m = d;
      k.deflection_rate_m_s = rate;
      k.vx_m_s = 5;
      k.spin_rad_s = 5 / m->calcRollingRadius(d);
      const double expected = std::max(0.0, Kz * d + Cz * rate);
      EXPECT_DOUBLE_EQ(m->calcNormalForce(k), expected) << "d " << d << ", rate " << rate;
      EXPECT_DOUBLE_EQ(m->calcForces(k).fz_N, expected) << "d " << d << ", rate " << rate;
    }
  // Numbers: 1.5e5 * 0.02 + 400 * 0.5 = 3200 N; 1.5e5 * 0.002 - 400 * 1 = -100 -> 0.
  EXPECT_DOUBLE_EQ(m->calcNormalForce({0.02, 0.5, 0, 0, 0, 0}), 3200.0);
  EXPECT_EQ(m->calcNormalForce({0.002, -1.0, 0, 0, 0, 0}), 0.0);
  // Energy Kz delta^2 / 2: 1.5e5 * 0.02^2 / 2 = 30 J; none off the ground.
  EXPECT_DOUBLE_EQ(m->calcPotentialEnergy(0.02), 30.0);
  EXPECT_DOUBLE_EQ(m->calcPotentialEnergy(0.013), 0.5 * Kz * 0.013 * 0.013);
  EXPECT_EQ(m->calcPotentialEnergy(0.0), 0.0);
  EXPECT_EQ(m->calcPotentialEnergy(-0.01), 0.0);
  // Its derivative is the spring force (central difference, quadratic: exact up to rounding).
  const double h = 1e-7, d = 0.02;
  EXPECT_NEAR((m->calcPotentialEnergy(d + h) - m->calcPotentialEnergy(d - h)) / (2 * h), Kz * d, 1e-6 * Kz * d);
  // Rolling radius Re = R1 - delta / 3.
  EXPECT_DOUBLE_EQ(m->calcRollingRadius(0.03), 0.30 - 0.01);
}

// --- Errors ----------------------------------------------------------------------------
TEST(TireErrors, NaNKinematicsNameTheField) {
  const auto m = makeModel("gim", BrushTireParams());
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const double inf = std::numeric_limits<double>::infinity();
  const ContactKinematics good{0.02, 0.0, 10.0, 0.5, 33.0, 0.0};
  const std::vector<std::pair<std::string, double ContactKinematics::*>> fields = {
      {"deflection_m", &ContactKinematics::deflection_m},
      {"deflection_rate_m_s", &ContactKinematics::deflection_rate_m_s},
      {"vx_m_s", &ContactKinematics::vx_m_s},
      {"vy_m_s", &ContactKinematics::vy_m_s},
      {"spin_rad_s", &ContactKinematics::spin_rad_s},
      {"camber_rad", &ContactKinematics::camber_rad}};
  for (const auto& [key, member] : fields)
    for (double bad : {nan, inf, -inf}) {
      ContactKinematics k = good;
      k.*member = bad;
      EXPECT_THROW(m->calcForces(k), Error) << key;
      const std::string msg = errorOf([&] { m->calcForces(k); });
      EXPECT_NE(msg.find(key), std::string::npos) << msg;
      EXPECT_NE(msg.find("finite"), std::string::npos) << msg;
    }
  // Even off the ground a NaN is an error, not a silent zero.
  ContactKinematics k = good;
  k.deflection_m = -0.1;
  k.vx_m_s = nan;
  EXPECT_NE(errorOf([&] { m->calcForces(k); }).find("vx_m_s"), std::string::npos);
}

TEST(TireErrors, NegativeCorneringStiffnessIsNamedWithItsValue) {
  BrushTireParams p;
  p.cornering_stiffness_N_per_rad = -1234.5;
  const std::string msg = errorOf([&] { p.validate("front tire"); });
  EXPECT_NE(msg.find("front tire.cornering_stiffness_N_per_rad"), std::string::npos) << msg;
  EXPECT_NE(msg.find("-1234.5"), std::string::npos) << msg;
  // The models validate their parameters on construction.
  EXPECT_THROW(GimTire tire(p), Error);
  const std::string msg2 = errorOf([&] { makeModel("fiala", p); });
  EXPECT_NE(msg2.find("cornering_stiffness_N_per_rad"), std::string::npos) << msg2;
  EXPECT_EQ(errorOf([] { BrushTireParams().validate(); }), "(no error)");
}

TEST(TireErrors, UnknownModelListsKnownOnes) {
  const std::string msg = errorOf([] { makeModel("foo", BrushTireParams()); });
  EXPECT_NE(msg.find("'foo'"), std::string::npos) << msg;
  EXPECT_NE(msg.find("fiala, gim, linear"), std::string::npos) << msg;
  for (const std::string& name : kAll) EXPECT_NE(makeModel(name, BrushTireParams()), nullptr) << name;
}

TEST(TireErrors, UnknownParameterKeyIsNamed) {
  const Json j = {{"mu_max", 0.9}, {"cornering_stiffnes_N_per_rad", 5e4}};
  const std::string msg = errorOf([&] { BrushTireParams::fromParams(ParamReader::fromJson(j, "car.json: tire")); });
  EXPECT_NE(msg.find("cornering_stiffnes_N_per_rad"), std::string::npos) << msg;
  EXPECT_NE(msg.find("car.json: tire"), std::string::npos) << msg;
  EXPECT_NE(msg.find("unknown key (did you mean 'cornering_stiffness_N_per_rad'?)"), std::string::npos) << msg;
  // Known keys are read, missing keys keep the defaults.
  const BrushTireParams p = BrushTireParams::fromParams(ParamReader::fromJson({{"mu_max", 0.9}}, "x"));
  EXPECT_EQ(p.mu_max, 0.9);
  EXPECT_EQ(p.cornering_stiffness_N_per_rad, BrushTireParams().cornering_stiffness_N_per_rad);
  // Values are range-checked through the same validate().
  const std::string msg3 = errorOf([] {
    BrushTireParams::fromParams(ParamReader::fromJson({{"longitudinal_stiffness_N", -2.0}}, "y"));
  });
  EXPECT_NE(msg3.find("longitudinal_stiffness_N"), std::string::npos) << msg3;
}

// The defaults are Table A.4, the same as the App. A data file's tire.
TEST(BrushTireParamsData, DefaultsMatchAppendixA) {
  const BrushTireParams file =
      BrushTireParams::fromParams(ParamReader::fromFile("appendix_a.json").child("tire").child("params"));
  const BrushTireParams def;
  const Json defJson = def.toJson();
  for (const auto& [key, value] : defJson.items()) EXPECT_EQ(file.toJson().at(key), value) << key;
  // Relaxation is off by default (the seed's steady-slip tire); the variant
  // file based on appendix_a.json turns it on and changes nothing else.
  EXPECT_FALSE(def.slip.hasRelaxation());
  const BrushTireParams relaxed =
      BrushTireParams::fromParams(ParamReader::fromFile("appendix_a_relaxation.json").child("tire").child("params"));
  EXPECT_EQ(relaxed.slip.relaxation_length_longitudinal_m, 0.25);
  EXPECT_EQ(relaxed.slip.relaxation_length_lateral_m, 0.5);
  EXPECT_EQ(relaxed.vertical.radial_stiffness_N_per_m, def.vertical.radial_stiffness_N_per_m);
  EXPECT_EQ(relaxed.mu_min, def.mu_min);
  EXPECT_EQ(def.vertical.unloaded_radius_m, 0.30);
  EXPECT_EQ(def.vertical.radial_stiffness_N_per_m, 1.5e5);
  EXPECT_EQ(def.longitudinal_stiffness_N, 8.0e4);
  EXPECT_EQ(def.cornering_stiffness_N_per_rad, 7.0e4);
  EXPECT_EQ(def.mu_max, 0.80);
  EXPECT_EQ(def.mu_min, 0.60);
  // toJson / fromParams round trip.
  const BrushTireParams back = BrushTireParams::fromParams(ParamReader::fromJson(def.toJson(), "rt"));
  for (const auto& [key, value] : defJson.items()) EXPECT_EQ(back.toJson().at(key), value) << key;
}

// --- Linear tire --------------------------------------------------------------------
// Fy = -C_a atan(Vy / Vx) and Fx = C_s (Omega Re - Vx) / Vx exactly (the same
// floating-point operations) above the low-speed threshold; no saturation.
TEST(TireLinear, ForcesAreLinearInTheSlips) {
  const BrushTireParams p;
  const auto m = makeModel("linear", p);
  for (double vx : {0.6, 3.0, 10.0, 40.0})
    for (double vy : {-50.0, -1.0, -0.01, 0.0, 0.2, 7.0})
      for (double kappa : {-1.0, -0.05, 0.0, 0.3}) {
        const ContactKinematics k = contact(*m, 4000.0, vx, vy, vx * (1 + kappa));
        const TireForces f = m->calcForces(k);
        const double vr = k.spin_rad_s * m->calcRollingRadius(k.deflection_m);
        EXPECT_EQ(f.fy_N, -p.cornering_stiffness_N_per_rad * std::atan(vy / vx)) << vx << " " << vy;
        EXPECT_EQ(f.fx_N, p.longitudinal_stiffness_N * (-(vx - vr) / vx)) << vx << " " << kappa;
        EXPECT_NEAR(f.fx_N, p.longitudinal_stiffness_N * kappa, 1e-9 * p.longitudinal_stiffness_N);
      }
  // No saturation: at tan(alpha) = 5 the force is C_a atan 5 = 9.6e4 N, far above mu Fz.
  const TireForces f = m->calcForces(contact(*m, 4000.0, 10.0, 50.0, 10.0));
  EXPECT_DOUBLE_EQ(f.fy_N, -7.0e4 * std::atan(5.0));
}

// With relaxation, the force law is evaluated at the transient slips; at the
// steady values kappa = (Omega Re - Vx) / |Vx|, tan alpha = Vy / |Vx| it must give
// the steady-slip tire's forces exactly (driving, braking, both directions).
TEST(TireRelaxation, TransientSlipAtItsSteadyValueGivesTheSteadyForces) {
  BrushTireParams p;
  p.camber_stiffness_N_per_rad = 2e3;
  BrushTireParams pr = p;
  pr.slip.relaxation_length_longitudinal_m = 0.25;
  pr.slip.relaxation_length_lateral_m = 0.5;
  for (const char* type : {"gim", "fiala", "linear"}) {
    const auto steady = makeModel(type, p), lag = makeModel(type, pr);
    for (double vx : {10.0, -7.0, 25.0})
      for (double spinFactor : {0.9, 0.97, 1.0, 1.04, 1.3})
        for (double vy : {-1.5, -0.2, 0.0, 0.3, 4.0}) {
          ContactKinematics k;
          k.deflection_m = 0.02;
          k.vx_m_s = vx;
          k.vy_m_s = vy;
          k.camber_rad = 0.01;
          const double Re = steady->calcRollingRadius(k.deflection_m);
          k.spin_rad_s = spinFactor * vx / Re;
          const TireForces f0 = steady->calcForces(k);
          ContactKinematics kt = k;
          kt.transient_slip = true;
          kt.kappa = (k.spin_rad_s * Re - vx) / std::abs(vx);
          kt.tan_alpha = vy / std::abs(vx);
          const TireForces f1 = lag->calcForces(kt);
          const double tol = 1e-9 * std::max(1.0, f0.fz_N);
          EXPECT_NEAR(f1.fx_N, f0.fx_N, tol) << type << " vx " << vx << " spin " << spinFactor << " vy " << vy;
          EXPECT_NEAR(f1.fy_N, f0.fy_N, tol) << type << " vx " << vx << " spin " << spinFactor << " vy " << vy;
          EXPECT_NEAR(f1.mz_N_m, f0.mz_N_m, tol) << type;
          EXPECT_NEAR(f1.slip_ratio, f0.slip_ratio, 1e-12) << type;
        }
  }
}

TEST(TireRelaxation, NegativeRelaxationLengthIsNamed) {
  BrushTireParams p;
  p.slip.relaxation_length_lateral_m = -0.1;
  EXPECT_EQ(errorOf([&] { p.validate("tire"); }), "tire.relaxation_length_lateral_m must not be negative, got -0.1");
}
