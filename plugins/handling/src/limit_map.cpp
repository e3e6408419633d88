#include "vdyn/handling/limit_map.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <ctime>
#include <limits>

namespace vdyn {

const FieldTable<LimitMapSettings>& LimitMapSettings::fields() {
  using S = LimitMapSettings;
  static const auto t =
      FieldTable<S>()
          .number("speed_start_m_s", &S::speed_start_m_s, "m/s",
                  "speed of the first fold (continuation in the front angle from straight running)")
          .number("speed_max_m_s", &S::speed_max_m_s, "m/s", "the fold curve is followed up to this speed")
          .number("speed_step_m_s", &S::speed_step_m_s, "m/s", "largest arclength step along the fold curve")
          .number("front_step_rad", &S::front_step_rad, "rad",
                  "largest step of the one-parameter continuation in the front angle")
          .number("front_max_rad", &S::front_max_rad, "rad", "no fold below this front angle: an error")
          .number("fold_tolerance_rad", &S::fold_tolerance_rad, "rad",
                  "bracket to which the one-parameter fold is located")
          .number("first_fold_tolerance_rad", &S::first_fold_tolerance_rad, "rad",
                  "a fold-curve point at a speed with several folds is the first fold from straight running when "
                  "within this of the one-parameter fold")
          .number("g_tolerance", &S::g_tolerance, "",
                  "|bordered test function g| at a converged fold-curve point, relative to the scaled Jacobian's "
                  "second-smallest singular value at the start")
          .integer("max_points", &S::max_points, "", "fold-curve points after the start")
          .number("force_tolerance_N", &S::force_tolerance_N, "N", "max |generalized-force residual|")
          .boolean("stability", &S::stability, "eigenvalues at every point (stable side)")
          .number("stability_tolerance_per_s", &S::stability_tolerance_per_s, "1/s",
                  "stable when every real part < -tolerance");
  return t;
}

LimitMapSettings LimitMapSettings::fromParams(const ParamReader& r) {
  LimitMapSettings s;
  fields().read(r, s);
  const auto pos = [&](double v, const char* k) {
    if (!(v > 0)) throw Error(r.at(k) + ": must be > 0, got " + formatValue(v));
  };
  pos(s.speed_start_m_s, "speed_start_m_s");
  pos(s.speed_step_m_s, "speed_step_m_s");
  pos(s.front_step_rad, "front_step_rad");
  pos(s.front_max_rad, "front_max_rad");
  pos(s.fold_tolerance_rad, "fold_tolerance_rad");
  pos(s.first_fold_tolerance_rad, "first_fold_tolerance_rad");
  pos(s.g_tolerance, "g_tolerance");
  pos(s.force_tolerance_N, "force_tolerance_N");
  pos(s.stability_tolerance_per_s, "stability_tolerance_per_s");
  if (!(s.speed_max_m_s > s.speed_start_m_s))
    throw Error(r.at("speed_max_m_s") + ": must exceed speed_start_m_s (" + formatValue(s.speed_start_m_s) +
                "), got " + formatValue(s.speed_max_m_s));
  if (s.max_points < 1) throw Error(r.at("max_points") + ": must be >= 1, got " + std::to_string(s.max_points));
  return s;
}

double locateFrontSteerFold(const HandlingVehicle& v, SteadyStateSolver& solver, double U,
                            const LimitMapSettings& set, Eigen::VectorXd* x, ArclengthResult* continuation) {
  v.holdSteering(U, 0);
  const SteadyStateResult straight = solver.solve(v.make_initial_state(U));
  ArclengthOptions o;
  o.step = 0.25 * set.front_step_rad;
  o.max_step = set.front_step_rad;
  o.min_step = set.fold_tolerance_rad;
  o.location_tolerance = set.fold_tolerance_rad;
  o.lambda_min = -set.front_step_rad;
  o.lambda_max = set.front_max_rad;
  o.max_points = 1000;
  o.stop_after_folds = 1;
  o.points_after_last_fold = 1;
  o.stability_tolerance = set.stability_tolerance_per_s;
  const auto drive = [&v, U](SimTK::State&, double df) { v.holdSteering(U, df); };
  ArclengthResult ar = continueSteadyState(solver, straight, 0.0, drive, set.front_step_rad, set.stability, o);
  const ArclengthSpecialPoint* fold = nullptr;
  for (const auto& sp : ar.special)
    if (sp.kind == "fold" && !fold) fold = &sp;
  if (!fold || !fold->located)
    throw Error("limit map: no fold of the steady turn in the front angle between 0 and front_max_rad = " +
                formatValue(set.front_max_rad) + " rad at " + formatValue(U) + " m/s (stopped: " + ar.stop_reason +
                ")");
  const double df = fold->point.lambda;
  if (x) *x = fold->point.x;
  if (continuation) *continuation = std::move(ar);
  return df;
}

LimitMapResult runLimitMap(const HandlingVehicle& v, const LimitMapSettings& set) {
  const auto w0 = std::chrono::steady_clock::now();
  const std::clock_t c0 = std::clock();
  v.validate();
  const Scene& sc = *v.scene;
  const SimTK::MobilizedBody& chassis = sc.getBody(v.chassis_body);
  SteadyStateOptions opt;
  opt.force_tolerance = set.force_tolerance_N;
  SteadyStateSolver solver(sc, makeSteadyTurningProblem(sc, v.chassis_body, v.wheel_bodies, 0.0), opt);
  LimitMapResult out;
  out.strategy = v.rear_strategy ? v.rear_strategy->name() : "2ws";

  // 1. The first fold, by continuation in delta_f at the start speed.
  const double U0 = set.speed_start_m_s;
  Eigen::VectorXd x0;
  ArclengthResult one;
  const double df0 = locateFrontSteerFold(v, solver, U0, set, &x0, &one);
  out.start_fold_front_rad = df0;
  out.start_steps = one.steps;
  for (const auto& sp : one.special)
    if (sp.kind == "fold") out.start_fold_bracket_rad = sp.bracket_length;
  const SteadyStateResult base = solver.makeDrivenResult(x0, df0);

  // 2. The fold curve in speed. The driven workspace holds one speed: a new
  // speed restarts it from `base` (its ineffective coordinates and time).
  double curU = std::numeric_limits<double>::quiet_NaN();
  const auto drive = [&v, &curU](SimTK::State& s, double df) {
    v.speed->setSpeed(s, curU);
    v.holdSteering(curU, df);
  };
  auto setSpeed = [&](double U) {
    if (U == curU) return;
    curU = U;
    solver.beginDriven(base, drive, set.front_step_rad);
  };
  TwoParameterSystem sys;
  sys.x_scale = solver.getUnknownScales();
  sys.r_scale = solver.getEquationScales();
  sys.p_scale = set.front_step_rad;
  // The arclength metric's speed scale: small against the steady state's
  // scaled change, so that a step's length is mostly speed.
  sys.mu_scale = 0.05 * set.speed_step_m_s;
  double lastU = U0, lastDf = df0;  // the last point the curve's corrector evaluated (the error below)
  sys.residual = [&](const Eigen::VectorXd& x, double df, double U) {
    lastU = U;
    lastDf = df;
    setSpeed(U);
    return solver.calcDrivenEquations(x, df);
  };
  sys.jacobian = [&](const Eigen::VectorXd& x, double df, double U, const Eigen::VectorXd& r) {
    setSpeed(U);
    return solver.calcDrivenJacobian(x, df, r);
  };
  sys.converged = [&solver](const Eigen::VectorXd& r) { return solver.meetsTolerances(r); };
  if (set.stability)
    sys.eigenvalues = [&](const Eigen::VectorXd& x, double df, double U) {
      setSpeed(U);
      return solver.calcStability(solver.makeDrivenResult(x, df), set.stability_tolerance_per_s).eigenvalues;
    };
  FoldCurveOptions fo;
  fo.g_tolerance = set.g_tolerance;
  fo.continuation.step = 0.25 * set.speed_step_m_s;
  fo.continuation.max_step = set.speed_step_m_s;
  fo.continuation.min_step = 1e-6 * set.speed_step_m_s;
  fo.continuation.lambda_min = U0 - set.speed_step_m_s;
  fo.continuation.lambda_max = set.speed_max_m_s;
  fo.continuation.max_points = set.max_points;
  fo.continuation.direction = +1;
  // g's gradient is a second difference (and the tire forces are only
  // piecewise smooth): the corrector converges linearly, in ~6-9 iterations.
  fo.continuation.fast_iterations = 6;
  fo.continuation.max_corrector_iterations = 14;
  fo.continuation.location_tolerance = 1e-3 * set.speed_step_m_s;
  fo.continuation.stability_tolerance = set.stability_tolerance_per_s;

  auto describe = [&](const Eigen::VectorXd& x, double df, double U, const ArclengthPoint& pt, double g) {
    setSpeed(U);
    const SteadyStateResult r = solver.makeDrivenResult(x, df);
    SimTK::State s = r.state;
    sc.getSystem().realize(s, SimTK::Stage::Velocity);
    LimitMapPoint p;
    p.speed_m_s = U;
    p.front_rad = df;
    p.rear_rad = v.rearAngle(U, df);
    p.lateral_accel_m_s2 = calcSteadyLateralAcceleration(chassis, s);
    p.yaw_rate_rad_s = chassis.getBodyAngularVelocity(s)[2];
    p.side_slip_rad = sc.evalOutput("chassis.side_slip_rad", s);
    p.fold_test = g;
    p.arclength = pt.s;
    p.kind = pt.kind;
    p.have_eigenvalues = pt.have_eigenvalues;
    p.eigenvalues = pt.eigenvalues;
    if (pt.have_eigenvalues && !pt.eigenvalues.empty()) {
      std::size_t k = 0;
      for (std::size_t i = 1; i < pt.eigenvalues.size(); ++i)
        if (std::abs(pt.eigenvalues[i]) < std::abs(pt.eigenvalues[k])) k = i;
      p.critical = pt.eigenvalues[k];
      double worst = -std::numeric_limits<double>::infinity();
      for (std::size_t i = 0; i < pt.eigenvalues.size(); ++i)
        if (i != k && pt.eigenvalues[i].real() > worst) worst = pt.eigenvalues[i].real(), p.least_damped_other = pt.eigenvalues[i];
      p.stable_side = worst < -set.stability_tolerance_per_s ? "straight_running" : "none";
    }
    return p;
  };
  for (const auto& sp : one.special)
    if (sp.kind == "hopf" && sp.point.lambda < df0) {
      curU = std::numeric_limits<double>::quiet_NaN();
      solver.beginDriven(base, [&v, U0](SimTK::State&, double df) { v.holdSteering(U0, df); }, set.front_step_rad);
      LimitMapPoint p = describe(sp.point.x, sp.point.lambda, U0, sp.point, 0);
      out.hopf_at_start.push_back(p);
    }
  curU = std::numeric_limits<double>::quiet_NaN();
  FoldCurveResult fc;
  try {
    fc = continueFoldCurve(sys, x0, df0, U0, fo);
  } catch (const Error& e) {
    throw Error("limit map (" + out.strategy + "): the fold curve could not pass speed " + formatValue(lastU) +
                " m/s, front angle " + formatValue(lastDf * 180 / SimTK::Pi) + " deg (the last point evaluated): " +
                e.what());
  }
  out.bordering = fc.bordering;
  for (const auto& fp : fc.points) out.points.push_back(describe(fp.x, fp.p, fp.mu, fp.point, fp.g));
  const int n = solver.numUnknowns();
  for (const auto& sp : fc.continuation.special) {
    LimitMapPoint p = describe(sp.point.x.head(n), sp.point.x[n], sp.point.lambda, sp.point, 0);
    p.kind = sp.kind;
    out.curve_special.push_back(p);
  }
  // 3. The strategy's limit: the first fold on the branch from straight
  // running. Where the curve crosses a point's speed once, that point is it;
  // where it crosses it several times (between folds of the curve in speed),
  // the one-parameter continuation at that speed says which one is (within
  // first_fold_tolerance_rad).
  LimitMapSettings quiet = set;
  quiet.stability = false;
  for (auto& p : out.points) {
    const double U = p.speed_m_s;
    // Segments of the curve (as drawn) whose closed speed range holds U, less
    // the interior points at U that the curve passes through monotonically
    // (counted by both their segments); a turning point at U counts twice.
    int crossings = 0;
    const auto& q = out.points;
    for (std::size_t j = 0; j + 1 < q.size(); ++j) {
      const double a = q[j].speed_m_s, b = q[j + 1].speed_m_s;
      crossings += std::min(a, b) <= U && U <= std::max(a, b);
    }
    for (std::size_t j = 1; j + 1 < q.size(); ++j)
      crossings -= q[j].speed_m_s == U && (q[j - 1].speed_m_s - U) * (q[j + 1].speed_m_s - U) < 0;
    p.folds_at_speed = std::max(crossings, 1);
    if (p.folds_at_speed > 1)
      p.first_fold = std::abs(locateFrontSteerFold(v, solver, U, quiet) - p.front_rad) <= set.first_fold_tolerance_rad;
  }
  out.stop_reason = fc.continuation.stop_reason;
  out.steps = fc.continuation.steps;
  out.rejected_steps = fc.continuation.rejected_steps;
  out.corrector_iterations = fc.continuation.corrector_iterations;
  out.residual_evaluations = fc.residual_evaluations;
  out.wall_time_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - w0).count();
  out.cpu_time_s = double(std::clock() - c0) / CLOCKS_PER_SEC;
  return out;
}

}  // namespace vdyn
