#include "vdyn/sensitivity/mixed.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <map>

#include "methods.h"
#include "vdyn/core/log.h"
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
// The mixed method in its parts, in the order DoCompute uses them:
//   NominalRun              the nominal simulation: psi and its steps (the
//                           coefficient nodes are chosen among them);
//   PerturbedModels         one model rebuilt at b + delta e_i per parameter
//                           (for R_b, a_b) and the initial sensitivity x_b(0);
//   CoefficientNodes        the coefficients A, B, y, y_x, y_b at a nominal
//                           step, computed once and kept for every pass;
//   SensitivityIntegration  the coefficients interpolated between the nodes
//                           and x_b' = A x_b + B integrated by two-stage Radau
//                           IIA with the cost's derivative, substeps doubled
//                           until their step-doubling estimate is small;
//   refineNodes             the next pass's nodes (bisection, then balancing).
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

/// The nominal run: the model built at the nominal design b0, simulated over
/// [t0, t0 + T] (Simbody, error-controlled) with every step's (t, q, u, z)
/// stored, and the cost psi of the run. The state x = (q, u, z) of the
/// sensitivity system is in Euler angles; its z are the auxiliary first-order
/// states (tire relaxation deflections), without the cost integral's z (the
/// integral's sensitivity is the quadrature of (4.47)).
struct NominalRun {
  NominalRun(const SensitivityProblem& p, const std::vector<double>& b0)
      : instance(p.model->build(b0)), scene(instance->updScene()), out(scene.getOutput(p.cost.output)) {
    const CostFunctional& cost = p.cost;
    const bool integral = cost.kind == CostKind::IntegralOfSquare;
    IntegralHandle psiHandle;
    if (integral) psiHandle = scene.addIntegralOfSquare(cost.output);
    start = toEulerAngles(scene, instance->makeInitialState());
    const SimTK::MultibodySystem& sys = scene.getSystem();
    const int zPsi = integral ? integralZIndex(scene, psiHandle, start) : -1;
    for (int j = 0; j < start.getNZ(); ++j)
      if (j != zPsi) zi.push_back(j);
    nq = start.getNQ();
    nu = start.getNU();
    nw = static_cast<int>(zi.size());
    n = nq + nu + nw;
    t0 = start.getTime();
    T = p.t_end_s;
    const double tEnd = t0 + T;
    // Inputs may switch on at t0 (the sine road starts there): coefficients at
    // the first grid point are the right-hand limits.
    tiny = 1e-10 * T;
    stage = out.stage > SimTK::Stage::Dynamics ? out.stage : SimTK::Stage(SimTK::Stage::Dynamics);

    double maxSample = -SimTK::Infinity;
    auto store = [&](const SimTK::State& st) {
      sys.realize(st, SimTK::Stage::Acceleration);
      samples.push_back({st.getTime(), toEigen(st.getQ()), toEigen(st.getU()), toEigen(st.getZ())});
      if (cost.kind == CostKind::Maximum) maxSample = std::max(maxSample, out.eval(st));
    };
    {
      SimTK::State s0 = start;
      s0.setTime(t0 + tiny);
      store(s0);
      samples.back().t = t0;
    }
    SimulationSettings sim;
    sim.t_end_s = tEnd;
    sim.report_interval_s = 0;
    sim.integrator = p.integrator;
    SimTK::State sEnd = start;
    const auto wall0 = std::chrono::steady_clock::now();
    simulate(scene, sEnd, sim, nullptr, store);
    if (samples.back().t < tEnd - 1e-12 * std::max(1.0, std::abs(tEnd))) store(sEnd);
    wall_time_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - wall0).count();
    switch (cost.kind) {
      case CostKind::IntegralOfSquare: psi = scene.getIntegral(psiHandle, sEnd); break;
      case CostKind::Maximum: psi = maxSample; break;
      case CostKind::FinalValue: psi = scene.evalOutput(cost.output, sEnd); break;
    }
  }
  /// Index of the last stored step.
  long finest() const { return static_cast<long>(samples.size()) - 1; }
  /// Time of step k from t0.
  double timeOf(long k) const { return samples[k].t - t0; }

  std::unique_ptr<DesignInstance> instance;
  Scene& scene;
  const Output out;          ///< the cost's output (a copy: the integral added after it)
  SimTK::State start;        ///< initial state, Euler angles
  std::vector<int> zi;       ///< indices of the auxiliary z among the state's z
  int nq = 0, nu = 0, nw = 0, n = 0;
  double t0 = 0, T = 0, tiny = 0;
  SimTK::Stage stage;        ///< realization stage of a residual evaluation (Dynamics, or the output's)
  std::vector<Sample> samples;
  double psi = 0;
  double wall_time_s = 0;
};

/// Per parameter b_i: the model rebuilt at b0 + delta_i e_i (delta_i =
/// kParamStep max(|b_i|, scale_i)), a workspace state of it, and the initial
/// sensitivity column x_b(0) = dx(0)/db_i, a central difference of the
/// model's initial state (e.g. its static equilibrium) at kInitialStep.
struct PerturbedModels {
  PerturbedModels(const SensitivityProblem& p, const std::vector<int>& idx, const std::vector<double>& b0,
                  const NominalRun& nom)
      : X0(nom.n, static_cast<int>(idx.size())) {
    const auto& params = p.model->getParameters();
    const int nq = nom.nq, nu = nom.nu, nw = nom.nw, n = nom.n;
    for (int c = 0; c < static_cast<int>(idx.size()); ++c) {
      const int i = idx[c];
      const double scale = std::max(std::abs(b0[i]), params[i].scale);
      std::vector<double> b = b0;
      delta.push_back(kParamStep * scale);
      b[i] += delta.back();
      models.push_back(p.model->build(b));
      const Scene& ps = models.back()->getScene();
      SimTK::State w = ps.getDefaultState();
      ps.getMatter().setUseEulerAngles(w, true);
      ps.getSystem().realizeModel(w);
      if (w.getNQ() != nq || w.getNU() != nu || w.getNZ() != nw)
        throw Error("mixed: perturbing " + params[i].name + " changed the state layout (nq, nu, nz)");
      work.push_back(w);
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
      if (logEnabled(LogLevel::Debug))
        logMessage(LogLevel::Debug, logFormat("mixed: x_b(0) column %d: %g %g", c, X0(0, c), X0(n - 1, c)));
    }
  }

  std::vector<std::unique_ptr<DesignInstance>> models;
  std::vector<SimTK::State> work;  ///< one workspace state per perturbed model
  std::vector<double> delta;       ///< the perturbation of each parameter
  MatrixXd X0;                     ///< initial sensitivity, n x r
};

/// The coefficients of x_b' = A x_b + B and of the cost's derivative at one
/// node: the output y, its derivatives y_x (n) and y_b (r).
struct Point {
  double y = 0;
  RowVectorXd y_x, y_b;
  MatrixXd A, B;
};

/// The coefficients at nominal steps, each computed on first use and kept
/// (every pass shares the nodes of the previous ones). At step k: the nominal
/// state is realized to Acceleration, A = [(N u)_x; U'_x; z'_x] comes from
/// the forward-difference residual Jacobians (evalJacobians) and the
/// factorized [M G^T; G 0]; column i of B and y_b are forward differences of
/// R, a, q', z' and y through perturbed model i at the nominal (q, u, u',
/// lambda) (4.44). Coefficient nodes are steps of the nominal run: their
/// states lie on the integrator's trajectory (an interpolated state between
/// steps would sit off the stiff tire modes' slow manifold and make the
/// coefficients rough).
class CoefficientNodes {
 public:
  CoefficientNodes(const NominalRun& nom, PerturbedModels& perturbed, const std::string& output)
      : nom_(nom), perturbed_(perturbed), output_(output), nomWork_(nom.start), colWork_(nom.start) {
    for (int j = 0; j < nom.nw; ++j) ziPerturbed_.push_back(j);  // the perturbed models carry no cost integral
  }

  /// The coefficients at nominal step k.
  const Point& at(long k) {
    auto it = points_.find(k);
    if (it != points_.end()) return it->second;
    const NominalRun& nom = nom_;
    const int nq = nom.nq, nu = nom.nu, nw = nom.nw, n = nom.n;
    const int r = static_cast<int>(perturbed_.models.size());
    const double t = k == 0 ? nom.t0 + nom.tiny : nom.samples[k].t;
    nomWork_.setTime(t);
    for (int i = 0; i < nq; ++i) nomWork_.updQ()[i] = nom.samples[k].q[i];
    for (int i = 0; i < nu; ++i) nomWork_.updU()[i] = nom.samples[k].u[i];
    for (int i = 0; i < nomWork_.getNZ(); ++i) nomWork_.updZ()[i] = nom.samples[k].z[i];
    nom.scene.getSystem().realize(nomWork_, SimTK::Stage::Acceleration);
    const PointJacobians J = evalJacobians(nom.scene, nomWork_, colWork_, &nom.out, nom.stage, false, nom.zi);
    evaluations_ += J.evaluations;
    const auto kkt = factorKkt(J);
    Point P;
    P.A = sensitivityMatrix(J, kkt);
    P.y = J.nominal.y;
    P.y_x = J.y_x;
    P.B.resize(n, r);
    P.y_b.resize(r);
    const int m = static_cast<int>(J.G.rows());
    for (int c = 0; c < r; ++c) {
      SimTK::State& w = perturbed_.work[c];
      const double delta = perturbed_.delta[c];
      w.setTime(t);
      w.updQ() = nomWork_.getQ();
      w.updU() = nomWork_.getU();
      for (int j = 0; j < nw; ++j) w.updZ()[j] = nomWork_.getZ()[nom.zi[j]];
      const Scene& ps = perturbed_.models[c]->getScene();
      PointEvaluator ev(ps, w, &ps.getOutput(output_), nom.stage, ziPerturbed_);
      const Eval e = ev.eval(nomWork_.getUDot(), nomWork_.getMultipliers());
      ++evaluations_;
      VectorXd rhs(nu + m);
      rhs << -(e.R - J.nominal.R) / delta, -(e.a - J.nominal.a) / delta;  // R_b, a_b (4.44)
      P.B.col(c) << (e.qdot - J.nominal.qdot) / delta, kkt.solve(rhs).head(nu), (e.zdot - J.nominal.zdot) / delta;
      P.y_b[c] = (e.y - J.nominal.y) / delta;
    }
    return points_.emplace(k, std::move(P)).first->second;
  }
  /// Steps whose coefficients were computed.
  std::size_t size() const { return points_.size(); }
  /// Residual evaluations (realizations) used so far.
  int evaluations() const { return evaluations_; }

 private:
  const NominalRun& nom_;
  PerturbedModels& perturbed_;
  std::string output_;
  std::vector<int> ziPerturbed_;
  SimTK::State nomWork_, colWork_;
  std::map<long, Point> points_;
  int evaluations_ = 0;
};

/// The linear sensitivity system on interpolated coefficients. The nodes are
/// indices of nominal steps (first and last included); the coefficients
/// between them are piecewise cubic Lagrange polynomials through the four
/// nearest nodes (error O(H^4) where the motion is smooth). On each node
/// interval, m substeps of two-stage Radau IIA (order 3, L-stable: the stiff
/// tire modes are damped at any step) integrate x_b' = A x_b + B from x_b(0),
/// and the cost's derivative d psi / d b is accumulated on the same stages.
/// No realization happens between nodes, so a substep costs only small dense
/// linear algebra.
class SensitivityIntegration {
 public:
  SensitivityIntegration(const NominalRun& nom, CoefficientNodes& points, const MatrixXd& X0, CostKind kind,
                         double tolerance, int initialIntervals)
      : nom_(nom), points_(points), X0_(X0), kind_(kind), tolerance_(tolerance) {
    const long finest = nom.finest();
    for (long j = 0; j <= initialIntervals; ++j) {
      const double tj = nom.t0 + nom.T * j / initialIntervals;
      long k = std::lower_bound(nom.samples.begin(), nom.samples.end(), tj,
                                [](const Sample& a, double v) { return a.t < v; }) -
               nom.samples.begin();
      k = std::min(k, finest);
      if (nodes_.empty() || k > nodes_.back()) nodes_.push_back(k);
    }
    if (nodes_.back() != finest) nodes_.push_back(finest);
    if (nodes_.size() < 4)
      throw Error("mixed: the nominal run took only " + std::to_string(finest) + " steps; at least 3 are needed");
  }

  /// d psi / d b on the current nodes: Radau with `substeps` and half as many
  /// per node interval; their difference / 7 (order 3) estimates the error
  /// of the finer one (`err`). The substeps double (from 2, kept across
  /// passes, at most 64) until that estimate is below a tenth of the
  /// tolerance relative for every parameter.
  RowVectorXd integrate(RowVectorXd& err) {
    RowVectorXd Sh = radau(substeps_ / 2);
    for (;;) {
      const RowVectorXd S = radau(substeps_);
      err = (S - Sh).cwiseAbs() / 7.0;  // order 3: estimate of the error of S
      bool ok = true;
      const double floor = 1e-14 * S.cwiseAbs().maxCoeff();
      for (int c = 0; c < S.size(); ++c) ok &= err[c] <= 0.1 * tolerance_ * std::abs(S[c]) + floor;
      if (ok || substeps_ >= 64) return S;
      Sh = S;
      substeps_ *= 2;
    }
  }

  /// The interpolation indicator of each node interval: the left- against the
  /// right-biased cubic at the interval's midpoint, every coefficient
  /// normalized by its largest magnitude over the nodes (0 where the two
  /// stencils coincide).
  std::vector<double> indicators() {
    const long M = static_cast<long>(nodes_.size());
    Coeff scale;
    {
      const Point& P = points_.at(nodes_[0]);
      scale.A = P.A.cwiseAbs();
      scale.B = P.B.cwiseAbs();
      scale.y = std::abs(P.y);
      scale.y_x = P.y_x.cwiseAbs();
      scale.y_b = P.y_b.cwiseAbs();
      for (long i = 1; i < M; ++i) {
        const Point& Q = points_.at(nodes_[i]);
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
      const double tau = 0.5 * (nom_.timeOf(nodes_[i]) + nom_.timeOf(nodes_[i + 1]));
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
  }

  const std::vector<long>& getNodes() const { return nodes_; }
  std::vector<long>& updNodes() { return nodes_; }
  int getSubsteps() const { return substeps_; }

 private:
  /// Interpolated coefficients at one time.
  struct Coeff {
    MatrixXd A, B;
    double y = 0;
    RowVectorXd y_x, y_b;
  };

  /// Cubic Lagrange weights of the 4 nodes from index i0 at tau.
  void weights(long i0, double tau, double w[4]) const {
    double x[4];
    for (int k = 0; k < 4; ++k) x[k] = nom_.timeOf(nodes_[i0 + k]);
    for (int k = 0; k < 4; ++k) {
      w[k] = 1;
      for (int l = 0; l < 4; ++l)
        if (l != k) w[k] *= (tau - x[l]) / (x[k] - x[l]);
    }
  }
  void combine(long i0, const double w[4], Coeff& c) {
    const Point* P[4] = {&points_.at(nodes_[i0]), &points_.at(nodes_[i0 + 1]), &points_.at(nodes_[i0 + 2]),
                         &points_.at(nodes_[i0 + 3])};
    c.A = w[0] * P[0]->A + w[1] * P[1]->A + w[2] * P[2]->A + w[3] * P[3]->A;
    c.B = w[0] * P[0]->B + w[1] * P[1]->B + w[2] * P[2]->B + w[3] * P[3]->B;
    c.y = w[0] * P[0]->y + w[1] * P[1]->y + w[2] * P[2]->y + w[3] * P[3]->y;
    c.y_x = w[0] * P[0]->y_x + w[1] * P[1]->y_x + w[2] * P[2]->y_x + w[3] * P[3]->y_x;
    c.y_b = w[0] * P[0]->y_b + w[1] * P[1]->y_b + w[2] * P[2]->y_b + w[3] * P[3]->y_b;
  }
  /// Interpolated coefficients at tau in node interval i (centred stencil).
  void interp(long i, double tau, Coeff& c) {
    const long M = static_cast<long>(nodes_.size());
    const long i0 = std::max(0L, std::min(M - 4, i - 1));
    double w[4];
    weights(i0, tau, w);
    combine(i0, w, c);
  }

  /// d psi / d b with m Radau substeps per node interval. Two-stage Radau
  /// IIA: c = (1/3, 1), a = [5/12 -1/12; 3/4 1/4], b = (3/4, 1/4). The cost
  /// integral uses the same stage values (Radau quadrature, order 3) of
  /// 2 y y_b (4.47); a final value is y_b at the end; a maximum is y_b at the
  /// time of the grid maximum, refined by a parabola through it.
  RowVectorXd radau(int m) {
    const int n = nom_.n, r = static_cast<int>(X0_.cols());
    const bool integral = kind_ == CostKind::IntegralOfSquare;
    const MatrixXd I = MatrixXd::Identity(n, n);
    MatrixXd Kmat(2 * n, 2 * n), Krhs(2 * n, r);
    MatrixXd X = X0_;
    RowVectorXd acc = RowVectorXd::Zero(r);
    std::vector<double> ys;
    std::vector<RowVectorXd> gs;  // y_b along the grid (maximum)
    Coeff c0, c1, c2;
    interp(0, 0.0, c0);
    auto yb = [&](const Coeff& c, const MatrixXd& Xj) -> RowVectorXd { return c.y_x * Xj + c.y_b; };
    if (kind_ == CostKind::Maximum) {
      ys.push_back(c0.y);
      gs.push_back(yb(c0, X));
    }
    for (std::size_t i = 0; i + 1 < nodes_.size(); ++i) {
      const double ta = nom_.timeOf(nodes_[i]), h = (nom_.timeOf(nodes_[i + 1]) - ta) / m;
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
        if (kind_ == CostKind::Maximum) {
          ys.push_back(c2.y);
          gs.push_back(yb(c2, X));
        }
        c0 = c2;
      }
    }
    if (kind_ == CostKind::FinalValue) return yb(c0, X);
    if (integral) return acc;
    // Maximum: d/db max_t y = y_b(t*) (t* interior); parabola through the grid maximum.
    const std::size_t j = std::max_element(ys.begin(), ys.end()) - ys.begin();
    if (j == 0 || j + 1 == ys.size()) return gs[j];
    const double ym = ys[j - 1], y0 = ys[j], yp = ys[j + 1];
    const double den = ym - 2 * y0 + yp;
    const double th = den != 0 ? std::max(-1.0, std::min(1.0, 0.5 * (ym - yp) / den)) : 0.0;
    return RowVectorXd(gs[j] + 0.5 * th * (gs[j + 1] - gs[j - 1]) +
                       0.5 * th * th * (gs[j + 1] - 2 * gs[j] + gs[j - 1]));
  }

  const NominalRun& nom_;
  CoefficientNodes& points_;
  const MatrixXd& X0_;
  CostKind kind_;
  double tolerance_;
  std::vector<long> nodes_;  // indices of nominal steps, first and last included
  int substeps_ = 2;
};

/// The next pass's nodes: every interval longer than one step is bisected
/// (uniform), or only those whose indicator `eta` is at least a tenth of the
/// largest (adaptive: kinks of the motion, the tire's adhesion/sliding
/// switches, get small intervals and smooth stretches long ones). Then
/// neighbouring intervals are kept within a factor 2 of each other, so every
/// cubic stencil is nearly uniform (uneven stencils amplify noise). Returns
/// false, leaving `nodes` alone, if no interval can be bisected (every one is
/// a single step, or every indicator is 0).
bool refineNodes(std::vector<long>& nodes, const std::vector<double>& eta, MixedRefinement refinement) {
  double etaMax = 0;
  for (std::size_t i = 0; i < eta.size(); ++i)
    if (nodes[i + 1] - nodes[i] > 1) etaMax = std::max(etaMax, eta[i]);
  if (!(etaMax > 0)) return false;
  const bool uniform = refinement == MixedRefinement::Uniform;
  std::vector<long> refined;
  for (std::size_t i = 0; i + 1 < nodes.size(); ++i) {
    refined.push_back(nodes[i]);
    if (nodes[i + 1] - nodes[i] > 1 && (uniform || eta[i] >= 0.1 * etaMax))
      refined.push_back((nodes[i] + nodes[i + 1]) / 2);
  }
  refined.push_back(nodes.back());
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
  return true;
}

/// True if every parameter's error estimate `est` is within the tolerance
/// relative to |d psi / d b_i| (`R`). A parameter whose normalized
/// sensitivity |d psi / d b_i| s_i (s_i = max(|b_i|, scale_i)) is below 1e-3
/// of the largest is held to that floor instead of its own (near-zero)
/// magnitude.
bool withinTolerance(const RowVectorXd& R, const RowVectorXd& est, double tolerance, const std::vector<int>& idx,
                     const std::vector<double>& b0, const std::vector<DesignParameter>& params) {
  const int r = static_cast<int>(R.size());
  bool converged = true;
  double normMax = 0;
  for (int c = 0; c < r; ++c)
    normMax = std::max(normMax, std::abs(R[c]) * std::max(std::abs(b0[idx[c]]), params[idx[c]].scale));
  for (int c = 0; c < r; ++c) {
    const double si = std::max(std::abs(b0[idx[c]]), params[idx[c]].scale);
    converged &= est[c] <= tolerance * std::max(std::abs(R[c]), 1e-3 * normMax / si);
  }
  return converged;
}

/// The nominal run, the perturbed models, then passes: integrate on the
/// current nodes, estimate the error of d psi / d b as the change from the
/// previous pass plus the integration's own estimate, and refine the nodes
/// until the estimate is below the tolerance.
SensitivityResult MixedMethod::DoCompute(const SensitivityProblem& p) const {
  const SensitivitySettings& set = settings();
  const auto idx = p.parameterIndices();
  const int r = static_cast<int>(idx.size());
  const auto& params = p.model->getParameters();
  const std::vector<double> b0 = p.model->getNominalValues();

  const NominalRun nom(p, b0);
  SensitivityResult res;
  res.nominal_wall_time_s = nom.wall_time_s;
  res.simulations = 1;
  res.psi = nom.psi;

  PerturbedModels perturbed(p, idx, b0, nom);
  CoefficientNodes points(nom, perturbed, p.cost.output);
  SensitivityIntegration integration(nom, points, perturbed.X0, p.cost.kind, set.tolerance, set.initial_intervals);

  RowVectorXd R_prev, R_cur, errInt, est = RowVectorXd::Constant(r, SimTK::Infinity);
  bool converged = false;
  for (int pass = 0;; ++pass) {
    R_cur = integration.integrate(errInt);
    if (logEnabled(LogLevel::Debug)) {
      std::string line = logFormat("mixed: pass %d nodes %zu substeps %d:", pass, integration.getNodes().size(),
                                   integration.getSubsteps());
      for (int c = 0; c < r; ++c) line += logFormat(" %.10g", R_cur[c]);
      logMessage(LogLevel::Debug, line);
    }
    if (pass >= 1) {
      est = (R_cur - R_prev).cwiseAbs() + errInt;
      converged = withinTolerance(R_cur, est, set.tolerance, idx, b0, params);
    }
    R_prev = R_cur;
    if (converged) break;
    if (!refineNodes(integration.updNodes(), integration.indicators(), set.refinement)) break;
  }
  if (!converged) {
    int worst = 0;
    for (int c = 1; c < r; ++c)
      if (est[c] / std::abs(R_cur[c]) > est[worst] / std::abs(R_cur[worst])) worst = c;
    throw Error("mixed: the sensitivity integration did not reach the tolerance " + formatValue(set.tolerance) +
                " with every one of the " + std::to_string(nom.finest()) +
                " nominal steps as a coefficient node: estimated relative error " +
                formatValue(est[worst] / std::abs(R_cur[worst])) + " for " + params[idx[worst]].name);
  }
  const std::size_t intervals = integration.getNodes().size() - 1;
  res.integration_steps = static_cast<int>(intervals * integration.getSubsteps());  // Radau steps
  res.grid_intervals = static_cast<int>(intervals);
  res.grid_points = static_cast<int>(points.size());
  res.residual_evaluations = points.evaluations();
  for (int c = 0; c < r; ++c) {
    res.dpsi_db.push_back(R_cur[c]);
    res.error_estimate.push_back(est[c]);
    res.perturbation.push_back(perturbed.delta[c]);
  }
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
