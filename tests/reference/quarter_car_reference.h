#pragma once
// A test-only second formulation of the seed's chapter 4 quarter car, steer
// locked or free (issue 25 item 1; docs/table_4_1.md, "The second formulation"):
// the chassis on its vertical slider and the App. A double-wishbone corner,
// written in minimal coordinates and integrated by its own fixed-step RK4. It
// uses no vdyn model and none of Simbody's multibody or constraint code, only
// SimTK's small vector types (Vec3, Mat33) for arithmetic.
//
// Coordinates and speeds. Independent: q = [z, theta1] (chassis height, lower
// arm angle about its pivot axis), speeds u = [z', theta1', phi'] (phi' the
// wheel spin; the wheel is axisymmetric about its spin axis, so its spin angle
// enters nothing). Dependent: the upper arm angle theta4, the knuckle's centre
// of mass p_GK and orientation R_GK, found each evaluation by Newton on the
// loop equations, written on the hardpoints:
//   g1 = p_G(lower ball on arm) - p_G(lower ball on knuckle) = 0   (joint 2)
//   g2 = p_G(upper ball on arm) - p_G(upper ball on knuckle) = 0   (joint 3)
//   g3 = (R_GK s_K) . x_G = 0                                     (steer lock)
// The dependent speeds w_d = [theta4', v_GK, w_GK] follow from the implicit
// function theorem, A_d w_d = -A_i u (A_d is the Newton Jacobian), and their
// rates from A_d w_d' = -A_i u' - gamma, gamma the velocity-product terms of
// d/dt (A w). The equations of motion are Kane's (virtual power):
//   sum_b [ (dv_b/du)^T (m_b a_b - F_b) + (dw_b/du)^T (I_b alpha_b + w_b x I_b w_b - T_b) ] = 0,
// which reduce to M_r(q) u' = Q_r(q, u, t), M_r = S^T M S, S = dw/du.
// With the steer free (QuarterCarRefData::steer_lock false, the seed's four
// degrees of freedom) g3 becomes (R_GK s_K) . x_G - sigma = 0 and sigma, sigma'
// are a fourth coordinate and speed.
//
// Forces: gravity on every body; the spring-damper between its chassis point
// and its lower-arm point, f = K (l - l0) + D l' along the line (4.43); the tire
// as vdyn's radial law with horizontal forces off: the contact point under the
// carcass centre p_GW + (R0 - rc) d (d the wheel plane's steepest-down
// direction), deflection delta = rc - clearance, Fz = Cz max(delta, 0) along
// the road normal z at that point; road height A sin(2 pi f t).
#include <cmath>
#include <functional>
#include <vector>

#include <Simbody.h>

namespace vdyn_reference {

using SimTK::Mat33;
using SimTK::Vec3;

struct QcBody {
  double m_kg = 0;
  Vec3 I_B_kg_m2{0};  ///< principal moments about the c.m., body axes (= chassis axes at design)
};

/// The data, in App. A's body frames (origin at each body's c.m., axes parallel
/// to the chassis frame in the tabulated configuration).
struct QuarterCarRefData {
  double chassis_mass_kg = 0, gravity_m_per_s2 = 0;
  QcBody lower_arm, knuckle, upper_arm, wheel;
  Vec3 p_CP1{0}, a1_C{0}, p_AP1{0};  ///< lower pivot: chassis point, axis (unit), lower-arm-frame point
  Vec3 p_AB2{0}, p_KB2{0};           ///< lower ball: on the lower arm, on the knuckle
  Vec3 p_CP4{0}, a4_C{0}, p_UP4{0};  ///< upper pivot: chassis point, axis (unit), upper-arm-frame point
  Vec3 p_UB3{0}, p_KB3{0};           ///< upper ball: on the upper arm, on the knuckle
  Vec3 s_K{0, 1, 0};                 ///< wheel spin axis, knuckle (= wheel) frame
  double K_N_per_m = 0, D_N_s_per_m = 0, l0_m = 0;
  Vec3 p_CS{0}, p_AS{0};  ///< spring: chassis point, lower-arm point
  double R0_m = 0, rc_m = 0, Cz_N_per_m = 0;  ///< tire unloaded radius, carcass radius, radial stiffness
  double road_A_m = 0, road_f_Hz = 0;
  /// true: g3 = (R_GK s_K) . x_G = 0 (3 dof); false: the knuckle steers freely
  /// about its kingpin (4 dof), sigma = (R_GK s_K) . x_G a fourth coordinate.
  bool steer_lock = true;
};

/// The 3 x 3 identity, written out (Mat33(1) trips GCC's -Warray-bounds in SimTK's Vec.h).
inline Mat33 identity3() { return Mat33(1, 0, 0, 0, 1, 0, 0, 0, 1); }

inline Mat33 skew(const Vec3& v) { return Mat33(0, -v[2], v[1], v[2], 0, -v[0], -v[1], v[0], 0); }

/// Rotation by angle t about unit axis a (Rodrigues).
inline Mat33 rotation(const Vec3& a, double t) {
  const Mat33 A = skew(a);
  return identity3() + std::sin(t) * A + (1 - std::cos(t)) * (A * A);
}

/// Gaussian elimination with partial pivoting on a dense n x n row-major A; solves A X = B for nrhs columns.
inline void solveDense(int n, std::vector<double> A, std::vector<double>& B, int nrhs) {
  for (int k = 0; k < n; ++k) {
    int piv = k;
    for (int i = k + 1; i < n; ++i)
      if (std::abs(A[i * n + k]) > std::abs(A[piv * n + k])) piv = i;
    if (piv != k) {
      for (int j = 0; j < n; ++j) std::swap(A[k * n + j], A[piv * n + j]);
      for (int j = 0; j < nrhs; ++j) std::swap(B[k * nrhs + j], B[piv * nrhs + j]);
    }
    for (int i = k + 1; i < n; ++i) {
      const double f = A[i * n + k] / A[k * n + k];
      if (f == 0) continue;
      for (int j = k; j < n; ++j) A[i * n + j] -= f * A[k * n + j];
      for (int j = 0; j < nrhs; ++j) B[i * nrhs + j] -= f * B[k * nrhs + j];
    }
  }
  for (int k = n - 1; k >= 0; --k)
    for (int j = 0; j < nrhs; ++j) {
      double s = B[k * nrhs + j];
      for (int i = k + 1; i < n; ++i) s -= A[k * n + i] * B[i * nrhs + j];
      B[k * nrhs + j] = s / A[k * n + k];
    }
}

class QuarterCarReference {
 public:
  explicit QuarterCarReference(const QuarterCarRefData& d) : d_(d) { resetLoopGuess(); }

  /// The loop's Newton start: App. A's tabulated body frames (upper arm at 0,
  /// knuckle unrotated at the wheel centre), at chassis height z.
  void resetLoopGuess(double z = 0) {
    th4_ = 0;
    R_GK_ = identity3();
    p_GK_ = wheelCentreInChassis() + Vec3(0, 0, z);
  }
  /// Knuckle (and wheel) origin in the chassis frame at design, through the tree joints.
  Vec3 wheelCentreInChassis() const { return d_.p_CP1 - d_.p_AP1 + d_.p_AB2 - d_.p_KB2; }

  /// Independent speeds: 3 with the steer locked, 4 with it free.
  int speeds() const { return d_.steer_lock ? 3 : 4; }

  struct Eval {
    double udot[4] = {0, 0, 0, 0};  ///< [z'', theta1'', phi'', sigma'']
    double Qr[4] = {0, 0, 0, 0};    ///< reduced generalized force at u' = 0 (static residual when u = 0)
    double Fz_N = 0;  ///< tire normal force
    double loop_residual_m = 0;
    int newton_iterations = 0;
  };

  /// The accelerations at time t_s for q = [z, theta1, sigma], u = [z', theta1', phi', sigma']
  /// (sigma, sigma' read only with the steer free).
  Eval evaluate(double t_s, const double q[3], const double u_in[4]) {
    Eval e;
    const int nu = speeds();
    const double z = q[0], th1 = q[1], sigma = d_.steer_lock ? 0.0 : q[2];
    const double u[4] = {u_in[0], u_in[1], u_in[2], d_.steer_lock ? 0.0 : u_in[3]};
    const Vec3 ez(0, 0, 1), ex(1, 0, 0);
    const Vec3 dz(0, 0, z);
    // Lower arm (joint 1): R_GA = rot(a1, theta1), c.m. and ball point in G.
    const Mat33 R_GA = rotation(d_.a1_C, th1);
    const Vec3 p_GP1 = d_.p_CP1 + dz;
    const Vec3 p_GA = p_GP1 - R_GA * d_.p_AP1;
    const Vec3 p_GB2 = p_GP1 + R_GA * (d_.p_AB2 - d_.p_AP1);
    const Vec3 p_GP4 = d_.p_CP4 + dz;
    // Close the loop: Newton on [theta4, p_GK, rotation increment of R_GK].
    double J[49], g[7];
    auto build = [&]() {
      const Mat33 R_GU = rotation(d_.a4_C, th4_);
      const Vec3 p_GB3 = p_GP4 + R_GU * (d_.p_UB3 - d_.p_UP4);
      const Vec3 r2 = R_GK_ * d_.p_KB2, r3 = R_GK_ * d_.p_KB3, s_G = R_GK_ * d_.s_K;
      const Vec3 g1 = p_GB2 - (p_GK_ + r2), g2 = p_GB3 - (p_GK_ + r3);
      for (int i = 0; i < 3; ++i) g[i] = g1[i], g[3 + i] = g2[i];
      g[6] = SimTK::dot(s_G, ex) - sigma;
      for (double& x : J) x = 0;
      const Mat33 S2 = skew(r2), S3 = skew(r3);
      const Vec3 t4 = SimTK::cross(d_.a4_C, p_GB3 - p_GP4);
      const Vec3 sx = SimTK::cross(s_G, ex);
      for (int i = 0; i < 3; ++i) {
        J[i * 7 + 1 + i] = -1;
        J[(3 + i) * 7 + 1 + i] = -1;
        J[(3 + i) * 7 + 0] = t4[i];
        for (int k = 0; k < 3; ++k) {
          J[i * 7 + 4 + k] = S2(i, k);
          J[(3 + i) * 7 + 4 + k] = S3(i, k);
        }
        J[6 * 7 + 4 + i] = sx[i];
      }
    };
    for (int it = 0; it < 30; ++it) {
      build();
      std::vector<double> A(J, J + 49), b(7);
      for (int i = 0; i < 7; ++i) b[i] = -g[i];
      solveDense(7, A, b, 1);
      th4_ += b[0];
      p_GK_ += Vec3(b[1], b[2], b[3]);
      const Vec3 rho(b[4], b[5], b[6]);
      const double ang = rho.norm();
      if (ang > 0) R_GK_ = rotation(rho / ang, ang) * R_GK_;
      double step = 0;
      for (double x : b) step = std::max(step, std::abs(x));
      e.newton_iterations = it + 1;
      if (step < 1e-13) break;
    }
    build();  // the Jacobian and residual at the converged configuration
    for (double x : g) e.loop_residual_m = std::max(e.loop_residual_m, std::abs(x));

    const Mat33 R_GU = rotation(d_.a4_C, th4_);
    const Vec3 p_GU = p_GP4 - R_GU * d_.p_UP4;
    const Vec3 p_GB3 = p_GP4 + R_GU * (d_.p_UB3 - d_.p_UP4);
    const Vec3 r2 = R_GK_ * d_.p_KB2, r3 = R_GK_ * d_.p_KB3, s_G = R_GK_ * d_.s_K;

    // Velocities: w = [z', theta1', phi', sigma', theta4', v_GK (3), w_GK (3)] = S u.
    // A_i (7 x 4) on [z', theta1', phi', sigma']; A_d = J on [theta4', v_GK, w_GK].
    std::vector<double> Ai(28, 0.0);
    const Vec3 t1 = SimTK::cross(d_.a1_C, p_GB2 - p_GP1);
    for (int i = 0; i < 3; ++i) {
      Ai[i * 4 + 0] = ez[i];
      Ai[i * 4 + 1] = t1[i];
      Ai[(3 + i) * 4 + 0] = ez[i];
    }
    Ai[6 * 4 + 3] = -1;  // g3 = s_G . x_G - sigma
    std::vector<double> Sd(28);
    for (int i = 0; i < 28; ++i) Sd[i] = -Ai[i];
    std::vector<double> Jd(J, J + 49);
    solveDense(7, Jd, Sd, 4);  // S_d = -A_d^-1 A_i
    double w[11] = {u[0], u[1], u[2], u[3]};
    for (int i = 0; i < 7; ++i) {
      w[4 + i] = 0;
      for (int j = 0; j < 4; ++j) w[4 + i] += Sd[i * 4 + j] * u[j];
    }
    const double th1d = u[1], phid = u[2], th4d = w[4];
    const Vec3 w_GK(w[8], w[9], w[10]);
    // gamma = (d/dt A) w: the velocity-product terms of the loop's accelerations.
    const Vec3 gam1 = th1d * th1d * SimTK::cross(d_.a1_C, SimTK::cross(d_.a1_C, p_GB2 - p_GP1)) -
                      SimTK::cross(w_GK, SimTK::cross(w_GK, r2));
    const Vec3 gam2 = th4d * th4d * SimTK::cross(d_.a4_C, SimTK::cross(d_.a4_C, p_GB3 - p_GP4)) -
                      SimTK::cross(w_GK, SimTK::cross(w_GK, r3));
    const double gam3 = SimTK::dot(ex, SimTK::cross(w_GK, SimTK::cross(w_GK, s_G)));
    std::vector<double> cd(7);
    for (int i = 0; i < 3; ++i) cd[i] = -gam1[i], cd[3 + i] = -gam2[i];
    cd[6] = -gam3;
    Jd.assign(J, J + 49);
    solveDense(7, Jd, cd, 1);  // c_d = -A_d^-1 gamma
    // S (11 x 4) and c (11): w' = S u' + c.
    double S[11][4] = {{1, 0, 0, 0}, {0, 1, 0, 0}, {0, 0, 1, 0}, {0, 0, 0, 1}}, c[11] = {0, 0, 0, 0};
    for (int i = 0; i < 7; ++i) {
      for (int j = 0; j < 4; ++j) S[4 + i][j] = Sd[i * 4 + j];
      c[4 + i] = cd[i];
    }

    // Bodies: v_b = Bv w, w_b = Bw w, a_b = Bv w' + kv, alpha_b = Bw w' + kw.
    double M[11][11] = {}, F[11] = {};
    struct BodyTerms {
      double m;
      Mat33 I_G;
      Vec3 p_G;            // c.m.
      double Bv[3][11], Bw[3][11];
      Vec3 kv, kw;
      Vec3 F, T;           // applied force at the c.m. and moment about it
    };
    auto zero = [](BodyTerms& b) {
      for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 11; ++j) b.Bv[i][j] = b.Bw[i][j] = 0;
      b.kv = b.kw = b.F = b.T = Vec3(0);
    };
    auto inertia = [](const QcBody& b, const Mat33& R) {
      const Mat33 I(b.I_B_kg_m2[0], 0, 0, 0, b.I_B_kg_m2[1], 0, 0, 0, b.I_B_kg_m2[2]);
      return R * I * ~R;
    };
    const double gr = d_.gravity_m_per_s2;
    BodyTerms ch, la, ua, kn, wh;
    for (BodyTerms* b : {&ch, &la, &ua, &kn, &wh}) zero(*b);
    ch.m = d_.chassis_mass_kg, ch.I_G = identity3(), ch.p_G = dz;
    ch.Bv[2][0] = 1;
    la.m = d_.lower_arm.m_kg, la.I_G = inertia(d_.lower_arm, R_GA), la.p_G = p_GA;
    {
      const Vec3 r = p_GA - p_GP1, t = SimTK::cross(d_.a1_C, r);
      for (int i = 0; i < 3; ++i) la.Bv[i][1] = t[i], la.Bw[i][1] = d_.a1_C[i];
      la.Bv[2][0] = 1;
      la.kv = th1d * th1d * SimTK::cross(d_.a1_C, SimTK::cross(d_.a1_C, r));
    }
    ua.m = d_.upper_arm.m_kg, ua.I_G = inertia(d_.upper_arm, R_GU), ua.p_G = p_GU;
    {
      const Vec3 r = p_GU - p_GP4, t = SimTK::cross(d_.a4_C, r);
      for (int i = 0; i < 3; ++i) ua.Bv[i][4] = t[i], ua.Bw[i][4] = d_.a4_C[i];
      ua.Bv[2][0] = 1;
      ua.kv = th4d * th4d * SimTK::cross(d_.a4_C, SimTK::cross(d_.a4_C, r));
    }
    kn.m = d_.knuckle.m_kg, kn.I_G = inertia(d_.knuckle, R_GK_), kn.p_G = p_GK_;
    // The wheel is axisymmetric about its spin axis: R_GW I_W R_GW^T = R_GK I_W R_GK^T.
    wh.m = d_.wheel.m_kg, wh.I_G = inertia(d_.wheel, R_GK_), wh.p_G = p_GK_;
    for (int i = 0; i < 3; ++i) {
      kn.Bv[i][5 + i] = kn.Bw[i][8 + i] = 1;
      wh.Bv[i][5 + i] = wh.Bw[i][8 + i] = 1;
      wh.Bw[i][2] = s_G[i];
    }
    wh.kw = phid * SimTK::cross(w_GK, s_G);
    auto velocity = [&](const BodyTerms& b, Vec3& v, Vec3& om) {
      v = om = Vec3(0);
      for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 11; ++j) v[i] += b.Bv[i][j] * w[j], om[i] += b.Bw[i][j] * w[j];
    };
    // Gravity (all bodies).
    for (BodyTerms* b : {&ch, &la, &ua, &kn, &wh}) b->F += Vec3(0, 0, -b->m * gr);
    // Spring-damper (4.43) from the chassis point to the lower arm point.
    {
      const Vec3 p_GSc = d_.p_CS + dz, p_GSa = p_GA + R_GA * d_.p_AS;
      const Vec3 dl = p_GSa - p_GSc;
      const double l = dl.norm();
      const Vec3 n = dl / l;
      Vec3 v, om;
      velocity(la, v, om);
      const Vec3 v_a = v + SimTK::cross(om, p_GSa - p_GA), v_c(0, 0, u[0]);
      const double ldot = SimTK::dot(n, v_a - v_c);
      const double f = d_.K_N_per_m * (l - d_.l0_m) + d_.D_N_s_per_m * ldot;  // tension, N
      la.F += -f * n;
      la.T += SimTK::cross(p_GSa - p_GA, -f * n);
      ch.F += f * n;
    }
    // Tire: radial force only, at the contact point under the carcass centre.
    {
      const Vec3 nrm(0, 0, 1);
      const double ns = SimTK::dot(nrm, s_G);
      Vec3 down = -nrm + ns * s_G;
      down /= down.norm();
      const Vec3 p_GC0 = p_GK_ + (d_.R0_m - d_.rc_m) * down;
      const double h = d_.road_A_m * std::sin(2 * SimTK::Pi * d_.road_f_Hz * t_s);
      const double clearance = p_GC0[2] - h;
      const double defl = d_.rc_m - clearance;
      if (defl > 0) {
        const Vec3 p_GC = p_GC0 - clearance * nrm;
        e.Fz_N = d_.Cz_N_per_m * defl;
        const Vec3 Fc = e.Fz_N * nrm;
        wh.F += Fc;
        wh.T += SimTK::cross(p_GC - p_GK_, Fc);
      }
    }
    // Assemble M (11 x 11) and F (11): F - (m kv; I kw + w x I w) projected.
    for (BodyTerms* b : {&ch, &la, &ua, &kn, &wh}) {
      Vec3 v, om;
      velocity(*b, v, om);
      const Vec3 fl = b->F - b->m * b->kv;
      const Vec3 tl = b->T - b->I_G * b->kw - SimTK::cross(om, b->I_G * om);
      for (int j = 0; j < 11; ++j) {
        for (int i = 0; i < 3; ++i) F[j] += b->Bv[i][j] * fl[i] + b->Bw[i][j] * tl[i];
        for (int k = 0; k < 11; ++k) {
          double s = 0;
          for (int i = 0; i < 3; ++i) {
            s += b->m * b->Bv[i][j] * b->Bv[i][k];
            for (int l = 0; l < 3; ++l) s += b->Bw[i][j] * b->I_G(i, l) * b->Bw[l][k];
          }
          M[j][k] += s;
        }
      }
    }
    // Reduce over the nu active speeds: M_r = S^T M S, Q_r = S^T (F - M c).
    std::vector<double> Mr(nu * nu, 0.0), Qr(nu, 0.0);
    double Fc[11];
    for (int j = 0; j < 11; ++j) {
      Fc[j] = F[j];
      for (int k = 0; k < 11; ++k) Fc[j] -= M[j][k] * c[k];
    }
    for (int a = 0; a < nu; ++a) {
      for (int j = 0; j < 11; ++j) Qr[a] += S[j][a] * Fc[j];
      for (int b = 0; b < nu; ++b)
        for (int j = 0; j < 11; ++j)
          for (int k = 0; k < 11; ++k) Mr[a * nu + b] += S[j][a] * M[j][k] * S[k][b];
    }
    for (int a = 0; a < nu; ++a) e.Qr[a] = Qr[a];
    solveDense(nu, Mr, Qr, 1);
    for (int a = 0; a < nu; ++a) e.udot[a] = Qr[a];
    return e;
  }

  /// Static equilibrium at t = 0 with u = 0: Newton on the reduced generalized
  /// forces of the coordinates [z, theta1 (, sigma)] (central-difference
  /// Jacobian; phi' has no force). q holds the start.
  /// `hold_sigma`: the steer held at q[2] (the rest of the corner at rest).
  void solveStatic(double q[3], double tol = 1e-9, bool hold_sigma = false) {
    const double u[4] = {0, 0, 0, 0};
    const int n = d_.steer_lock || hold_sigma ? 2 : 3;
    const int row[3] = {0, 1, 3};  // the speeds of z, theta1, sigma
    for (int it = 0; it < 50; ++it) {
      const Eval e0 = evaluate(0, q, u);
      double res = 0;
      for (int i = 0; i < n; ++i) res = std::max(res, std::abs(e0.Qr[row[i]]));
      if (res < tol) return;
      std::vector<double> Jm(n * n), b(n);
      for (int j = 0; j < n; ++j) {
        double qp[3] = {q[0], q[1], q[2]}, qm[3] = {q[0], q[1], q[2]};
        qp[j] += 1e-7, qm[j] -= 1e-7;
        const Eval ep = evaluate(0, qp, u), em = evaluate(0, qm, u);
        for (int i = 0; i < n; ++i) Jm[i * n + j] = (ep.Qr[row[i]] - em.Qr[row[i]]) / 2e-7;
      }
      for (int i = 0; i < n; ++i) b[i] = -e0.Qr[row[i]];
      solveDense(n, Jm, b, 1);
      for (int i = 0; i < n; ++i) q[i] += b[i];
    }
    throw std::runtime_error("quarter car reference: static equilibrium did not converge");
  }

  struct Run {
    double psi = 0;       ///< int_0^T z''^2 dt (4.46), m^2/s^3
    double z0_m = 0, theta1_0_rad = 0, sigma0 = 0;
    double max_abs_sigma = 0;  ///< largest |s_G . x_G| of the run (0 with the steer locked)
    double sigma_walk = 0;     ///< where the steer walk stopped (steer free)
    /// The steer's generalized force one walk step before and at the stop: a
    /// rise through 0 with sigma (-, then + for a walk to +sigma) is an
    /// unstable rest pose (negative stiffness), a fall a stable one.
    double Q_sigma_before_N_m = 0, Q_sigma_after_N_m = 0;
    double max_loop_residual_m = 0;
    double min_Fz_N = 1e300;
    int steps = 0;
  };

  /// From static equilibrium at t = 0, classical RK4 with a fixed step dt over
  /// [0, T]; psi is a further state integrated with the same stages. With the
  /// steer free, the static solve starts from the steer found by walking sigma
  /// from 0 in steps of 0.01, the rest of the corner at rest at each, in the
  /// direction `steer_walk` (+1 or -1; 0: the way its generalized force pushes
  /// at sigma = 0), until that force changes sign. Without horizontal tire
  /// forces the free steer has more than one rest pose (docs/table_4_1.md).
  Run simulate(double T_s, double dt_s, int steer_walk = 0) {
    Run r;
    double q[3] = {d_.R0_m - wheelCentreInChassis()[2], 0.0, 0.0};
    resetLoopGuess(q[0]);
    if (!d_.steer_lock) {
      const double u0[4] = {0, 0, 0, 0};
      solveStatic(q, 1e-9, true);
      const double Q0 = evaluate(0, q, u0).Qr[3];
      const double dir = steer_walk != 0 ? steer_walk : (Q0 > 0 ? 1 : -1);
      r.Q_sigma_before_N_m = Q0;
      for (int k = 1; k < 99; ++k) {
        q[2] = dir * 0.01 * k;
        solveStatic(q, 1e-9, true);
        const double Q = evaluate(0, q, u0).Qr[3];
        if (Q * r.Q_sigma_before_N_m <= 0) {
          r.Q_sigma_after_N_m = Q;
          break;
        }
        r.Q_sigma_before_N_m = Q;
      }
      r.sigma_walk = q[2];
    }
    solveStatic(q);
    r.z0_m = q[0], r.theta1_0_rad = q[1], r.sigma0 = q[2];
    const int n = static_cast<int>(std::llround(T_s / dt_s));
    const double h = T_s / n;
    // y = [z, theta1, sigma, z', theta1', phi', sigma', psi]
    constexpr int N = 8;
    double y[N] = {q[0], q[1], q[2], 0, 0, 0, 0, 0};
    auto f = [&](double t, const double* yy, double* dy) {
      const double qq[3] = {yy[0], yy[1], yy[2]}, uu[4] = {yy[3], yy[4], yy[5], yy[6]};
      const Eval e = evaluate(t, qq, uu);
      r.max_loop_residual_m = std::max(r.max_loop_residual_m, e.loop_residual_m);
      r.min_Fz_N = std::min(r.min_Fz_N, e.Fz_N);
      r.max_abs_sigma = std::max(r.max_abs_sigma, std::abs(qq[2]));
      dy[0] = yy[3], dy[1] = yy[4], dy[2] = d_.steer_lock ? 0.0 : yy[6];
      for (int i = 0; i < 4; ++i) dy[3 + i] = e.udot[i];
      dy[7] = e.udot[0] * e.udot[0];
    };
    double k1[N], k2[N], k3[N], k4[N], yt[N];
    for (int s = 0; s < n; ++s) {
      const double t = s * h;
      f(t, y, k1);
      for (int i = 0; i < N; ++i) yt[i] = y[i] + 0.5 * h * k1[i];
      f(t + 0.5 * h, yt, k2);
      for (int i = 0; i < N; ++i) yt[i] = y[i] + 0.5 * h * k2[i];
      f(t + 0.5 * h, yt, k3);
      for (int i = 0; i < N; ++i) yt[i] = y[i] + h * k3[i];
      f(t + h, yt, k4);
      for (int i = 0; i < N; ++i) y[i] += h / 6 * (k1[i] + 2 * k2[i] + 2 * k3[i] + k4[i]);
    }
    r.steps = n;
    r.psi = y[7];
    return r;
  }

 private:
  QuarterCarRefData d_;
  double th4_ = 0;
  Vec3 p_GK_{0};
  Mat33 R_GK_ = identity3();
};

}  // namespace vdyn_reference
