#include "vdyn/sensitivity/mixed.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <map>

#include "methods.h"
#include "vdyn/core/simulation.h"

namespace vdyn {

using Eigen::MatrixXd;
using Eigen::RowVectorXd;
using Eigen::VectorXd;

namespace {

VectorXd toEigen(const SimTK::Vector& v) {
  VectorXd e(v.size());
  for (int i = 0; i < v.size(); ++i) e[i] = v[i];
  return e;
}

MatrixXd toEigen(const SimTK::Matrix& m) {
  MatrixXd e(m.nrow(), m.ncol());
  for (int i = 0; i < m.nrow(); ++i)
    for (int j = 0; j < m.ncol(); ++j) e(i, j) = m(i, j);
  return e;
}

/// Relative finite-difference step of the state variables (about sqrt(machine eps)).
constexpr double kStateStep = 1.5e-8;
/// Relative finite-difference step of the design parameters for r_b (4.44):
/// a little larger than sqrt(eps) because body-fixed offsets (s') enter
/// positions of about 1 m, whose round-off is 2e-16 m.
constexpr double kParamStep = 1e-7;
/// Relative perturbation of the central difference of the initial state.
constexpr double kInitialStep = 1e-3;

/// Residual, constraint errors, q' and the output at the work state's (t, q, u)
/// for fixed (u', lambda).
struct Eval {
  VectorXd R, a, qdot, udot, zdot;  // zdot: of the auxiliary z only
  double y = 0;
};

class PointEvaluator {
 public:
  /// `zi`: indices of the auxiliary z (tire relaxation states) among the
  /// state's z; their derivatives are realized at Stage::Dynamics.
  PointEvaluator(const Scene& scene, SimTK::State& work, const Output* out, SimTK::Stage stage,
                 const std::vector<int>& zi)
      : scene_(scene), sys_(scene.getSystem()), matter_(scene.getMatter()), work_(work), out_(out), stage_(stage),
        zi_(zi) {}

  Eval eval(const SimTK::Vector& udot, const SimTK::Vector& lambda) {
    sys_.realize(work_, stage_);
    ++evaluations;
    matter_.calcResidualForce(work_, sys_.getMobilityForces(work_, SimTK::Stage::Dynamics),
                              sys_.getRigidBodyForces(work_, SimTK::Stage::Dynamics), udot, lambda, R_);
    matter_.calcConstraintAccelerationErrors(work_, udot, a_);
    Eval e;
    e.R = toEigen(R_);
    e.a = toEigen(a_);
    e.qdot = toEigen(work_.getQDot());
    if (stage_ >= SimTK::Stage::Acceleration) e.udot = toEigen(work_.getUDot());
    e.zdot.resize(zi_.size());
    for (std::size_t j = 0; j < zi_.size(); ++j) e.zdot[j] = work_.getZDot()[zi_[j]];
    if (out_) e.y = out_->eval(work_);
    return e;
  }
  int evaluations = 0;

 private:
  const Scene& scene_;
  const SimTK::MultibodySystem& sys_;
  const SimTK::SimbodyMatterSubsystem& matter_;
  SimTK::State& work_;
  const Output* out_;
  SimTK::Stage stage_;
  std::vector<int> zi_;
  SimTK::Vector R_, a_;
};

/// The Jacobians of one point plus the output's total derivative y_x and the
/// nominal values (R0 ~ 0, a0 ~ 0, q'0, y0) the parameter columns subtract.
struct PointJacobians : ResidualJacobians {
  RowVectorXd y_x;
  Eval nominal;
};

/// `state` must be realized to Acceleration (its u', lambda are the fixed values).
/// Columns: q, u, then the auxiliary z listed in `zi`.
PointJacobians evalJacobians(const Scene& scene, const SimTK::State& state, SimTK::State& work, const Output* out,
                             SimTK::Stage stage, bool withForwardDynamics, const std::vector<int>& zi) {
  const int nq = state.getNQ(), nu = state.getNU(), nw = static_cast<int>(zi.size()), n = nq + nu + nw;
  const SimTK::Vector& udot = state.getUDot();
  const SimTK::Vector& lambda = state.getMultipliers();
  work.setTime(state.getTime());
  work.updQ() = state.getQ();
  work.updU() = state.getU();
  if (state.getNZ()) work.updZ() = state.getZ();
  if (withForwardDynamics) stage = SimTK::Stage::Acceleration;
  PointEvaluator ev(scene, work, out, stage, zi);
  PointJacobians J;
  J.nominal = ev.eval(udot, lambda);
  const int m = static_cast<int>(J.nominal.a.size());
  J.R_x.resize(nu, n);
  J.a_x.resize(m, n);
  J.qdot_x.resize(nq, n);
  J.zdot_x.resize(nw, n);
  J.y_x.resize(n);
  if (withForwardDynamics) J.udot_x.resize(nu, n);
  auto column = [&](int j, double h) {
    const Eval e = ev.eval(udot, lambda);
    J.R_x.col(j) = (e.R - J.nominal.R) / h;  // (4.30)-(4.32), (4.34)-(4.37)
    J.a_x.col(j) = (e.a - J.nominal.a) / h;  // (4.33), (4.38)
    J.qdot_x.col(j) = (e.qdot - J.nominal.qdot) / h;
    J.zdot_x.col(j) = (e.zdot - J.nominal.zdot) / h;  // z_b' = f_z,x x_b + f_z,b
    J.y_x[j] = (e.y - J.nominal.y) / h;
    if (withForwardDynamics) J.udot_x.col(j) = (e.udot - J.nominal.udot) / h;
  };
  for (int j = 0; j < nq; ++j) {
    const double q = state.getQ()[j], h = kStateStep * std::max(std::abs(q), 1.0);
    work.updQ()[j] = q + h;
    column(j, h);
    work.updQ()[j] = q;
  }
  for (int j = 0; j < nu; ++j) {
    const double u = state.getU()[j], h = kStateStep * std::max(std::abs(u), 1.0);
    work.updU()[j] = u + h;
    column(nq + j, h);
    work.updU()[j] = u;
  }
  for (int j = 0; j < nw; ++j) {
    const double z = state.getZ()[zi[j]], h = kStateStep * std::max(std::abs(z), 1.0);
    work.updZ()[zi[j]] = z + h;
    column(nq + nu + j, h);
    work.updZ()[zi[j]] = z;
  }
  SimTK::Matrix M, G;
  scene.getMatter().calcM(state, M);
  scene.getMatter().calcG(state, G);
  J.M = toEigen(M);
  J.G = G.nrow() ? toEigen(G) : MatrixXd(0, nu);
  J.evaluations = ev.evaluations;
  return J;
}

/// [M G^T; G 0], factorized once per point and shared by A and every B column.
Eigen::PartialPivLU<MatrixXd> factorKkt(const ResidualJacobians& J) {
  const int nu = static_cast<int>(J.M.rows()), m = static_cast<int>(J.G.rows());
  MatrixXd K = MatrixXd::Zero(nu + m, nu + m);
  K.topLeftCorner(nu, nu) = J.M;
  K.topRightCorner(nu, m) = J.G.transpose();
  K.bottomLeftCorner(m, nu) = J.G;
  return K.partialPivLu();
}

MatrixXd sensitivityMatrix(const ResidualJacobians& J, const Eigen::PartialPivLU<MatrixXd>& kkt) {
  const int nq = static_cast<int>(J.qdot_x.rows()), nu = static_cast<int>(J.M.rows());
  const int nw = static_cast<int>(J.zdot_x.rows());
  const int m = static_cast<int>(J.G.rows()), n = nq + nu + nw;
  MatrixXd rhs(nu + m, n);
  rhs.topRows(nu) = -J.R_x;
  rhs.bottomRows(m) = -J.a_x;
  MatrixXd A(n, n);
  A.topRows(nq) = J.qdot_x;
  A.middleRows(nq, nu) = kkt.solve(rhs).topRows(nu);  // (4.24), (4.27): u'_b = U' x_b + ...
  A.bottomRows(nw) = J.zdot_x;
  return A;
}

// ---------------------------------------------------------------------------
class MixedMethod : public SensitivityMethod {
 public:
  explicit MixedMethod(SensitivitySettings s) : SensitivityMethod("mixed", s) {}

 protected:
  SensitivityResult DoCompute(const SensitivityProblem& p) const override;
};

struct Sample {
  double t;
  VectorXd q, u, z;  // z: all of the state's z (cost integral included)
};

/// Index of the cost integral among the z of `s` (-1 if none): the z whose
/// change moves the integral's value.
int integralZIndex(const Scene& sc, IntegralHandle h, const SimTK::State& s) {
  const double v0 = sc.getIntegral(h, s);
  for (int j = 0; j < s.getNZ(); ++j) {
    SimTK::State w = s;
    w.updZ()[j] += 1;
    if (sc.getIntegral(h, w) != v0) return j;
  }
  throw Error("mixed: the cost integral's state variable was not found among the " + std::to_string(s.getNZ()) +
              " z of the scene");
}

SensitivityResult MixedMethod::DoCompute(const SensitivityProblem& p) const {
  const auto wall0 = std::chrono::steady_clock::now();
  const SensitivitySettings& set = settings();
  const auto idx = p.parameterIndices();
  const int r = static_cast<int>(idx.size());
  const auto& params = p.model->getParameters();
  const std::vector<double> b0 = p.model->getNominalValues();
  const CostFunctional& cost = p.cost;
  const bool integral = cost.kind == CostKind::IntegralOfSquare;

  // --- nominal run, its steps stored for interpolation ----------------------
  auto nominal = p.model->build(b0);
  Scene& sc = nominal->updScene();
  const Output out = sc.getOutput(cost.output);
  IntegralHandle psiHandle;
  if (integral) psiHandle = sc.addIntegralOfSquare(cost.output);
  SimTK::State s = toEulerAngles(sc, nominal->makeInitialState());
  const SimTK::MultibodySystem& sys = sc.getSystem();
  const SimTK::SimbodyMatterSubsystem& matter = sc.getMatter();
  // Auxiliary first-order states (tire relaxation deflections) join q and u
  // in x; the cost integral's z is left out (its sensitivity is the
  // quadrature of (4.47) below).
  const int zPsi = integral ? integralZIndex(sc, psiHandle, s) : -1;
  std::vector<int> zi;
  for (int j = 0; j < s.getNZ(); ++j)
    if (j != zPsi) zi.push_back(j);
  const int nq = s.getNQ(), nu = s.getNU(), nw = static_cast<int>(zi.size()), n = nq + nu + nw;
  std::vector<int> ziPerturbed(nw);  // the perturbed models carry no cost integral
  for (int j = 0; j < nw; ++j) ziPerturbed[j] = j;
  const double t0 = s.getTime(), T = p.t_end_s, tEnd = t0 + T;
  // Inputs may switch on at t0 (the sine road starts there): coefficients at
  // the first grid point are the right-hand limits.
  const double tiny = 1e-10 * T;
  const SimTK::Stage stage = out.stage > SimTK::Stage::Dynamics ? out.stage : SimTK::Stage(SimTK::Stage::Dynamics);

  std::vector<Sample> samples;
  double maxSample = -SimTK::Infinity;
  auto store = [&](const SimTK::State& st) {
    sys.realize(st, SimTK::Stage::Acceleration);
    samples.push_back({st.getTime(), toEigen(st.getQ()), toEigen(st.getU()), toEigen(st.getZ())});
    if (cost.kind == CostKind::Maximum) maxSample = std::max(maxSample, out.eval(st));
  };
  {
    SimTK::State s0 = s;
    s0.setTime(t0 + tiny);
    store(s0);
    samples.back().t = t0;
  }
  SimulationSettings sim;
  sim.t_end_s = tEnd;
  sim.report_interval_s = 0;
  sim.integrator = p.integrator;
  SimTK::State sEnd = s;
  const auto nominal0 = std::chrono::steady_clock::now();
  simulate(sc, sEnd, sim, nullptr, store);
  if (samples.back().t < tEnd - 1e-12 * std::max(1.0, std::abs(tEnd))) store(sEnd);
  SensitivityResult res;
  res.nominal_wall_time_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - nominal0).count();
  res.simulations = 1;
  switch (cost.kind) {
    case CostKind::IntegralOfSquare: res.psi = sc.getIntegral(psiHandle, sEnd); break;
    case CostKind::Maximum: res.psi = maxSample; break;
    case CostKind::FinalValue: res.psi = sc.evalOutput(cost.output, sEnd); break;
  }

  // --- perturbed models: r_b (4.44) and the initial sensitivity -------------
  std::vector<std::unique_ptr<DesignInstance>> perturbed;
  std::vector<SimTK::State> pwork;
  std::vector<double> delta;
  MatrixXd X0(n, r);
  for (int c = 0; c < r; ++c) {
    const int i = idx[c];
    const double scale = std::max(std::abs(b0[i]), params[i].scale);
    std::vector<double> b = b0;
    delta.push_back(kParamStep * scale);
    b[i] += delta.back();
    perturbed.push_back(p.model->build(b));
    const Scene& ps = perturbed.back()->getScene();
    SimTK::State w = ps.getDefaultState();
    ps.getMatter().setUseEulerAngles(w, true);
    ps.getSystem().realizeModel(w);
    if (w.getNQ() != nq || w.getNU() != nu || w.getNZ() != nw)
      throw Error("mixed: perturbing " + params[i].name + " changed the state layout (nq, nu, nz)");
    pwork.push_back(w);
    // Initial state x(0; b) (e.g. a static equilibrium): central difference.
    const double h0 = kInitialStep * scale;
    VectorXd x[2];
    for (int k = 0; k < 2; ++k) {
      std::vector<double> bk = b0;
      bk[i] += k == 0 ? h0 : -h0;
      auto inst = p.model->build(bk);
      const SimTK::State sk = toEulerAngles(inst->getScene(), inst->makeInitialState());
      x[k].resize(n);
      x[k].head(nq) = toEigen(sk.getQ());
      x[k].segment(nq, nu) = toEigen(sk.getU());
      for (int j = 0; j < nw; ++j) x[k][nq + nu + j] = sk.getZ()[j];
    }
    X0.col(c) = (x[0] - x[1]) / (2 * h0);
    if (std::getenv("VDYN_DEBUG_MIXED")) std::fprintf(stderr, "X0 col %d: %g %g\n", c, X0(0, c), X0(n - 1, c));
  }

  // --- coefficient matrices at grid points (shared by all levels) -----------
  // Coefficient nodes are steps of the nominal run: their states lie on the
  // integrator's trajectory (an interpolated state between steps would sit off
  // the stiff tire modes' slow manifold and make the coefficients rough).
  const int N0 = set.initial_intervals;
  const long finest = static_cast<long>(samples.size()) - 1;
  struct Point {
    double y = 0;
    RowVectorXd y_x, y_b;
    MatrixXd A, B;
  };
  std::map<long, Point> points;
  SimTK::State nomWork = s, colWork = s;
  auto point = [&](long k) -> const Point& {
    auto it = points.find(k);
    if (it != points.end()) return it->second;
    const double t = k == 0 ? t0 + tiny : samples[k].t;
    nomWork.setTime(t);
    for (int i = 0; i < nq; ++i) nomWork.updQ()[i] = samples[k].q[i];
    for (int i = 0; i < nu; ++i) nomWork.updU()[i] = samples[k].u[i];
    for (int i = 0; i < nomWork.getNZ(); ++i) nomWork.updZ()[i] = samples[k].z[i];
    sys.realize(nomWork, SimTK::Stage::Acceleration);
    const PointJacobians J = evalJacobians(sc, nomWork, colWork, &out, stage, false, zi);
    res.residual_evaluations += J.evaluations;
    const auto kkt = factorKkt(J);
    Point P;
    P.A = sensitivityMatrix(J, kkt);
    P.y = J.nominal.y;
    P.y_x = J.y_x;
    P.B.resize(n, r);
    P.y_b.resize(r);
    const int m = static_cast<int>(J.G.rows());
    for (int c = 0; c < r; ++c) {
      SimTK::State& w = pwork[c];
      w.setTime(t);
      w.updQ() = nomWork.getQ();
      w.updU() = nomWork.getU();
      for (int j = 0; j < nw; ++j) w.updZ()[j] = nomWork.getZ()[zi[j]];
      PointEvaluator ev(perturbed[c]->getScene(), w, &perturbed[c]->getScene().getOutput(cost.output), stage,
                        ziPerturbed);
      const Eval e = ev.eval(nomWork.getUDot(), nomWork.getMultipliers());
      ++res.residual_evaluations;
      VectorXd rhs(nu + m);
      rhs << -(e.R - J.nominal.R) / delta[c], -(e.a - J.nominal.a) / delta[c];  // R_b, a_b (4.44)
      P.B.col(c) << (e.qdot - J.nominal.qdot) / delta[c], kkt.solve(rhs).head(nu), (e.zdot - J.nominal.zdot) / delta[c];
      P.y_b[c] = (e.y - J.nominal.y) / delta[c];
    }
    return points.emplace(k, std::move(P)).first->second;
  };

  // --- the linear sensitivity system on interpolated coefficients -----------
  // The coefficients are sampled at nodes (indices on a finest grid of
  // N0 2^max_levels intervals) and interpolated by piecewise cubic Lagrange
  // polynomials through the four nearest nodes (error O(H^4) where the motion
  // is smooth). The linear system is integrated by the trapezoidal rule with m
  // substeps per node interval, and Richardson extrapolation from m/2 and m
  // substeps (its estimate, a tenth of the tolerance, sets m). No realization
  // happens between nodes, so the integration step costs only small dense
  // linear algebra. The nodes adapt: each pass bisects the intervals whose
  // interpolation indicator (left- against right-biased cubic at the
  // midpoint, all coefficients normalized by their largest magnitude) is at
  // least a tenth of the largest, so kinks of the motion (the tire's
  // adhesion/sliding switches) get small intervals and smooth stretches long
  // ones. The error estimate of d psi / d b is the change from the previous
  // pass plus the integration estimate; passes continue until it is below the
  // tolerance.
  const MatrixXd I = MatrixXd::Identity(n, n);
  struct Coeff {
    MatrixXd A, B;
    double y = 0;
    RowVectorXd y_x, y_b;
  };
  std::vector<long> nodes;  // indices of nominal steps, first and last included
  for (long j = 0; j <= N0; ++j) {
    const double tj = t0 + T * j / N0;
    long k = std::lower_bound(samples.begin(), samples.end(), tj, [](const Sample& a, double v) { return a.t < v; }) -
             samples.begin();
    k = std::min(k, finest);
    if (nodes.empty() || k > nodes.back()) nodes.push_back(k);
  }
  if (nodes.back() != finest) nodes.push_back(finest);
  if (nodes.size() < 4)
    throw Error("mixed: the nominal run took only " + std::to_string(finest) + " steps; at least 3 are needed");
  auto timeOf = [&](long k) { return samples[k].t - t0; };
  /// Cubic Lagrange weights of the 4 nodes from index i0 at tau.
  auto weights = [&](long i0, double tau, double w[4]) {
    double x[4];
    for (int k = 0; k < 4; ++k) x[k] = timeOf(nodes[i0 + k]);
    for (int k = 0; k < 4; ++k) {
      w[k] = 1;
      for (int l = 0; l < 4; ++l)
        if (l != k) w[k] *= (tau - x[l]) / (x[k] - x[l]);
    }
  };
  auto combine = [&](long i0, const double w[4], Coeff& c) {
    const Point* P[4] = {&point(nodes[i0]), &point(nodes[i0 + 1]), &point(nodes[i0 + 2]), &point(nodes[i0 + 3])};
    c.A = w[0] * P[0]->A + w[1] * P[1]->A + w[2] * P[2]->A + w[3] * P[3]->A;
    c.B = w[0] * P[0]->B + w[1] * P[1]->B + w[2] * P[2]->B + w[3] * P[3]->B;
    c.y = w[0] * P[0]->y + w[1] * P[1]->y + w[2] * P[2]->y + w[3] * P[3]->y;
    c.y_x = w[0] * P[0]->y_x + w[1] * P[1]->y_x + w[2] * P[2]->y_x + w[3] * P[3]->y_x;
    c.y_b = w[0] * P[0]->y_b + w[1] * P[1]->y_b + w[2] * P[2]->y_b + w[3] * P[3]->y_b;
  };
  /// Interpolated coefficients at tau in node interval i (centred stencil).
  auto interp = [&](long i, double tau, Coeff& c) {
    const long M = static_cast<long>(nodes.size());
    const long i0 = std::max(0L, std::min(M - 4, i - 1));
    double w[4];
    weights(i0, tau, w);
    combine(i0, w, c);
  };
  // Two-stage Radau IIA (order 3, L-stable: the stiff tire modes are damped
  // at any step): c = (1/3, 1), a = [5/12 -1/12; 3/4 1/4], b = (3/4, 1/4).
  // The cost integral uses the same stage values (Radau quadrature, order 3).
  MatrixXd Kmat(2 * n, 2 * n), Krhs(2 * n, r);
  auto radau = [&](int m) -> RowVectorXd {
    MatrixXd X = X0;
    RowVectorXd acc = RowVectorXd::Zero(r);
    std::vector<double> ys;
    std::vector<RowVectorXd> gs;  // y_b along the grid (maximum)
    Coeff c0, c1, c2;
    interp(0, 0.0, c0);
    auto yb = [&](const Coeff& c, const MatrixXd& Xj) -> RowVectorXd { return c.y_x * Xj + c.y_b; };
    if (cost.kind == CostKind::Maximum) {
      ys.push_back(c0.y);
      gs.push_back(yb(c0, X));
    }
    for (std::size_t i = 0; i + 1 < nodes.size(); ++i) {
      const double ta = timeOf(nodes[i]), h = (timeOf(nodes[i + 1]) - ta) / m;
      for (int j = 0; j < m; ++j) {
        interp(static_cast<long>(i), ta + (j + 1.0 / 3.0) * h, c1);
        interp(static_cast<long>(i), ta + (j + 1.0) * h, c2);
        Kmat.topLeftCorner(n, n) = I - (5.0 / 12.0) * h * c1.A;
        Kmat.topRightCorner(n, n) = (1.0 / 12.0) * h * c1.A;
        Kmat.bottomLeftCorner(n, n) = -0.75 * h * c2.A;
        Kmat.bottomRightCorner(n, n) = I - 0.25 * h * c2.A;
        Krhs.topRows(n) = c1.A * X + c1.B;
        Krhs.bottomRows(n) = c2.A * X + c2.B;
        const MatrixXd K = Kmat.partialPivLu().solve(Krhs);
        const MatrixXd X1 = X + h * ((5.0 / 12.0) * K.topRows(n) - (1.0 / 12.0) * K.bottomRows(n));
        const MatrixXd X2 = X + h * (0.75 * K.topRows(n) + 0.25 * K.bottomRows(n));  // stiffly accurate
        if (integral) acc += h * (0.75 * 2 * c1.y * yb(c1, X1) + 0.25 * 2 * c2.y * yb(c2, X2));  // (4.47)
        X = X2;
        if (cost.kind == CostKind::Maximum) {
          ys.push_back(c2.y);
          gs.push_back(yb(c2, X));
        }
        c0 = c2;
      }
    }
    if (cost.kind == CostKind::FinalValue) return yb(c0, X);
    if (integral) return acc;
    // Maximum: d/db max_t y = y_b(t*) (t* interior); parabola through the grid maximum.
    const std::size_t j = std::max_element(ys.begin(), ys.end()) - ys.begin();
    if (j == 0 || j + 1 == ys.size()) return gs[j];
    const double ym = ys[j - 1], y0 = ys[j], yp = ys[j + 1];
    const double den = ym - 2 * y0 + yp;
    const double th = den != 0 ? std::max(-1.0, std::min(1.0, 0.5 * (ym - yp) / den)) : 0.0;
    return RowVectorXd(gs[j] + 0.5 * th * (gs[j + 1] - gs[j - 1]) +
                       0.5 * th * th * (gs[j + 1] - 2 * gs[j] + gs[j - 1]));
  };
  int substeps = 2;
  auto integrate = [&](RowVectorXd& err) -> RowVectorXd {
    RowVectorXd Sh = radau(substeps / 2);
    for (;;) {
      const RowVectorXd S = radau(substeps);
      err = (S - Sh).cwiseAbs() / 7.0;  // order 3: estimate of the error of S
      bool ok = true;
      const double floor = 1e-14 * S.cwiseAbs().maxCoeff();
      for (int c = 0; c < r; ++c) ok &= err[c] <= 0.1 * set.tolerance * std::abs(S[c]) + floor;
      if (ok || substeps >= 64) return S;
      Sh = S;
      substeps *= 2;
    }
  };
  /// Interpolation indicator of each node interval.
  auto indicators = [&]() {
    const long M = static_cast<long>(nodes.size());
    // Normalization: the largest magnitude of each coefficient over the nodes.
    Coeff scale;
    {
      const Point& P = point(nodes[0]);
      scale.A = P.A.cwiseAbs();
      scale.B = P.B.cwiseAbs();
      scale.y = std::abs(P.y);
      scale.y_x = P.y_x.cwiseAbs();
      scale.y_b = P.y_b.cwiseAbs();
      for (long i = 1; i < M; ++i) {
        const Point& Q = point(nodes[i]);
        scale.A = scale.A.cwiseMax(Q.A.cwiseAbs());
        scale.B = scale.B.cwiseMax(Q.B.cwiseAbs());
        scale.y = std::max(scale.y, std::abs(Q.y));
        scale.y_x = scale.y_x.cwiseMax(Q.y_x.cwiseAbs());
        scale.y_b = scale.y_b.cwiseMax(Q.y_b.cwiseAbs());
      }
    }
    auto inv = [](double v) { return v > 0 ? 1.0 / v : 0.0; };
    const MatrixXd sA = scale.A.unaryExpr(inv), sB = scale.B.unaryExpr(inv);
    const RowVectorXd sx = scale.y_x.unaryExpr(inv), sb = scale.y_b.unaryExpr(inv);
    const double sy = inv(scale.y);
    std::vector<double> eta(M - 1, 0.0);
    for (long i = 0; i + 1 < M; ++i) {
      const double tau = 0.5 * (timeOf(nodes[i]) + timeOf(nodes[i + 1]));
      const long iL = std::max(0L, std::min(M - 4, i - 2)), iR = std::max(0L, std::min(M - 4, i - 1 + 1));
      if (iL == iR) continue;
      double w[4];
      Coeff L, R;
      weights(iL, tau, w);
      combine(iL, w, L);
      weights(iR, tau, w);
      combine(iR, w, R);
      double e = std::abs(L.y - R.y) * sy;
      e = std::max(e, (L.A - R.A).cwiseAbs().cwiseProduct(sA).maxCoeff());
      e = std::max(e, (L.B - R.B).cwiseAbs().cwiseProduct(sB).maxCoeff());
      e = std::max(e, (L.y_x - R.y_x).cwiseAbs().cwiseProduct(sx).maxCoeff());
      e = std::max(e, (L.y_b - R.y_b).cwiseAbs().cwiseProduct(sb).maxCoeff());
      eta[i] = e;
    }
    return eta;
  };

  RowVectorXd R_prev, R_cur, errInt, est = RowVectorXd::Constant(r, SimTK::Infinity);
  bool converged = false;
  int pass = 0;
  const bool uniformRefinement = !std::getenv("VDYN_MIXED_ADAPTIVE");
  for (;; ++pass) {
    R_cur = integrate(errInt);
    if (std::getenv("VDYN_DEBUG_MIXED")) {
      std::fprintf(stderr, "mixed pass %d nodes %zu substeps %d:", pass, nodes.size(), substeps);
      for (int c = 0; c < r; ++c) std::fprintf(stderr, " %.10g", R_cur[c]);
      std::fprintf(stderr, "\n");
    }
    if (pass >= 1) {
      est = (R_cur - R_prev).cwiseAbs() + errInt;
      converged = true;
      // A parameter whose normalized sensitivity |d psi / d b_i| s_i (s_i =
      // max(|b_i|, scale_i)) is below 1e-3 of the largest is held to that
      // floor instead of its own (near-zero) magnitude.
      double normMax = 0;
      for (int c = 0; c < r; ++c)
        normMax = std::max(normMax, std::abs(R_cur[c]) * std::max(std::abs(b0[idx[c]]), params[idx[c]].scale));
      for (int c = 0; c < r; ++c) {
        const double si = std::max(std::abs(b0[idx[c]]), params[idx[c]].scale);
        converged &= est[c] <= set.tolerance * std::max(std::abs(R_cur[c]), 1e-3 * normMax / si);
      }
    }
    R_prev = R_cur;
    if (converged) break;
    // Refine: bisect the intervals with the largest indicators.
    const std::vector<double> eta = indicators();
    double etaMax = 0;
    for (std::size_t i = 0; i < eta.size(); ++i)
      if (nodes[i + 1] - nodes[i] > 1) etaMax = std::max(etaMax, eta[i]);
    if (!(etaMax > 0)) break;
    std::vector<long> refined;
    for (std::size_t i = 0; i + 1 < nodes.size(); ++i) {
      refined.push_back(nodes[i]);
      if (nodes[i + 1] - nodes[i] > 1 && (uniformRefinement || eta[i] >= 0.1 * etaMax)) refined.push_back((nodes[i] + nodes[i + 1]) / 2);
    }
    refined.push_back(nodes.back());
    // Keep neighbouring intervals within a factor 2 of each other, so every
    // cubic stencil is nearly uniform (uneven stencils amplify noise).
    for (bool changed = true; changed;) {
      changed = false;
      std::vector<long> balanced{refined[0]};
      for (std::size_t i = 0; i + 1 < refined.size(); ++i) {
        const long len = refined[i + 1] - refined[i];
        const long left = i > 0 ? refined[i] - refined[i - 1] : len;
        const long right = i + 2 < refined.size() ? refined[i + 2] - refined[i + 1] : len;
        if (len > 1 && (len > 2 * left || len > 2 * right)) {
          balanced.push_back((refined[i] + refined[i + 1]) / 2);
          changed = true;
        }
        balanced.push_back(refined[i + 1]);
      }
      refined.swap(balanced);
    }
    nodes.swap(refined);
  }
  if (!converged) {
    int worst = 0;
    for (int c = 1; c < r; ++c)
      if (est[c] / std::abs(R_cur[c]) > est[worst] / std::abs(R_cur[worst])) worst = c;
    throw Error("mixed: the sensitivity integration did not reach the tolerance " + formatValue(set.tolerance) +
                " with every one of the " + std::to_string(finest) +
                " nominal steps as a coefficient node: estimated relative error " +
                formatValue(est[worst] / std::abs(R_cur[worst])) + " for " + params[idx[worst]].name);
  }
  res.integration_steps = static_cast<int>((nodes.size() - 1) * substeps);  // Radau steps
  res.grid_intervals = static_cast<int>(nodes.size() - 1);
  res.grid_points = static_cast<int>(points.size());
  for (int c = 0; c < r; ++c) {
    res.dpsi_db.push_back(R_cur[c]);
    res.error_estimate.push_back(est[c]);
    res.perturbation.push_back(delta[c]);
  }
  (void)wall0;
  (void)matter;
  return res;
}

}  // namespace

// ---------------------------------------------------------------------------

ResidualJacobians calcResidualJacobians(const Scene& scene, const SimTK::State& state, SimTK::State& work,
                                        bool withForwardDynamics) {
  scene.getSystem().realize(state, SimTK::Stage::Acceleration);
  std::vector<int> zi(state.getNZ());
  for (int j = 0; j < state.getNZ(); ++j) zi[j] = j;
  return evalJacobians(scene, state, work, nullptr, SimTK::Stage::Dynamics, withForwardDynamics, zi);
}

MatrixXd calcSensitivityMatrix(const ResidualJacobians& J) { return sensitivityMatrix(J, factorKkt(J)); }

namespace detail {
std::unique_ptr<SensitivityMethod> makeMixedMethod(const SensitivitySettings& s) {
  return std::make_unique<MixedMethod>(s);
}
}  // namespace detail

}  // namespace vdyn
