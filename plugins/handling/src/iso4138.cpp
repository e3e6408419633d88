#include "vdyn/handling/iso4138.h"

#include <chrono>
#include <cmath>

namespace vdyn {

void ConstantRadiusSettings::validate() const {
  requireFinite(radius_m, "constant radius radius_m");
  if (!(std::abs(radius_m) > 0)) throw Error("constant radius radius_m must be non-zero, got " + formatValue(radius_m));
  requirePositive(speed_start_m_s, "constant radius speed_start_m_s");
  requirePositive(speed_step_m_s, "constant radius speed_step_m_s");
  requirePositive(limit_tolerance_m_s, "constant radius limit_tolerance_m_s");
  if (past_limit_points < 0)
    throw Error("constant radius past_limit_points must be >= 0, got " + std::to_string(past_limit_points));
  if (!(speed_max_m_s >= speed_start_m_s))
    throw Error("constant radius speed_max_m_s (" + formatValue(speed_max_m_s) + ") is below speed_start_m_s (" +
                formatValue(speed_start_m_s) + ")");
}

const FieldTable<ConstantRadiusSettings>& ConstantRadiusSettings::fields() {
  using S = ConstantRadiusSettings;
  static const auto t =
      FieldTable<S>()
          .number("radius_m", &S::radius_m, "m", "path radius of the chassis origin")
          .number("speed_start_m_s", &S::speed_start_m_s, "m/s", "first speed")
          .number("speed_step_m_s", &S::speed_step_m_s, "m/s", "speed increment")
          .number("speed_max_m_s", &S::speed_max_m_s, "m/s", "last speed tried")
          .number("limit_tolerance_m_s", &S::limit_tolerance_m_s, "m/s",
                  "arclength bracket to which the limit (the fold in speed) is located, and the continuation's "
                  "smallest step")
          .integer("past_limit_points", &S::past_limit_points, "",
                   "pseudo-arclength points continued past the limit (the unstable branch at lower speeds)")
          .boolean("stability", &S::stability, "eigenvalues at each point");
  return t;
}

ConstantRadiusSettings ConstantRadiusSettings::fromParams(const ParamReader& r) {
  ConstantRadiusSettings s;
  fields().read(r, s);
  s.validate();
  return s;
}

ConstantRadiusResult runConstantRadius(const HandlingVehicle& v, const ConstantRadiusSettings& set) {
  using clock = std::chrono::steady_clock;
  const auto t0 = clock::now();
  set.validate();
  v.validate();
  const Scene& sc = *v.scene;
  const SimTK::MobilizedBody ch = sc.getBody(v.chassis_body);
  const double R = set.radius_m;
  // Path radius: U_h - r R = 0 (m/s).
  SteadyStateSolver solver(sc, makeSteeringUnknownProblem(v, "path radius U_h - r R (m/s)", 1e-10,
                                                          [ch, R](const SimTK::State& s) {
                                                            const SimTK::Vec3 vel = ch.getBodyOriginVelocity(s);
                                                            return std::hypot(vel[0], vel[1]) -
                                                                   ch.getBodyAngularVelocity(s)[2] * R;
                                                          }),
                           set.solver);
  ConstantRadiusResult out;
  out.radius_m = R;
  out.wheelbase_m = v.wheelbase_m;

  // Start: straight running at the first speed, steered to the Ackermann angle.
  const double U0 = set.speed_start_m_s;
  SimTK::State start = v.make_initial_state(U0);
  v.holdSteering(U0, v.wheelbase_m / R);

  auto measure = [&](double U, const SteadyStateResult& r) {
    ConstantRadiusPoint p;
    p.speed_m_s = U;
    SimTK::State s = r.state;  // a copy: realize it again
    sc.getSystem().realize(s, SimTK::Stage::Velocity);
    p.yaw_rate_rad_s = ch.getBodyAngularVelocity(s)[2];
    p.lateral_accel_m_s2 = calcSteadyLateralAcceleration(ch, s);
    const SimTK::Vec3 vel = ch.getBodyOriginVelocity(s);
    p.path_radius_m = std::hypot(vel[0], vel[1]) / p.yaw_rate_rad_s;
    p.front_rad = r.parameters.at(0);
    p.rear_rad = v.rearAngle(U, p.front_rad);
    p.side_slip_rad = sc.evalOutput("chassis.side_slip_rad", s);
    p.roll_rad = sc.evalOutput("chassis.roll_rad", s);
    SimTK::State sa = r.state;  // another copy, realized through Stage::Acceleration
    sc.getSystem().realize(sa, SimTK::Stage::Acceleration);
    p.speed_hold_force_N = v.speed->calcForce(sa);
    p.iterations = r.iterations;
    p.residual_evaluations = r.residual_evaluations;
    p.solve_wall_time_s = r.wall_time_s;
    out.solve_wall_time_s += r.wall_time_s;
    out.residual_evaluations += r.residual_evaluations;
    if (set.stability) {
      const auto ts = clock::now();
      const StabilityResult st = solver.calcStability(r);
      p.stable = st.stable;
      p.least_damped = st.least_damped;
      p.stability_wall_time_s = std::chrono::duration<double>(clock::now() - ts).count();
      out.stability_wall_time_s += p.stability_wall_time_s;
    }
    return p;
  };
  auto setSpeed = [&](SimTK::State& s, double U) { v.speed->setSpeed(s, U); };

  // Continuation in speed with a quadratic predictor (followSteadyState), one
  // speed at a time so that the branch's end can be bisected.
  std::vector<std::pair<double, SteadyStateResult>> branch;
  auto solveAt = [&](double U) {
    std::vector<ContinuationPoint> pts;
    if (branch.empty()) {
      pts = followSteadyState(solver, start, {U}, setSpeed);
    } else {
      // Restart the continuation from the last (up to) three points so its
      // predictor extrapolates along the branch.
      SteadyStateResult guess = branch.back().second;
      setSpeed(guess.euler_state, U);
      const std::size_t k = std::min<std::size_t>(3, branch.size());
      if (k >= 2) {
        Eigen::VectorXd xp = Eigen::VectorXd::Zero(solver.numUnknowns());
        for (std::size_t i = branch.size() - k; i < branch.size(); ++i) {
          double w = 1;
          for (std::size_t j = branch.size() - k; j < branch.size(); ++j)
            if (j != i) w *= (U - branch[j].first) / (branch[i].first - branch[j].first);
          xp += w * solver.getUnknowns(branch[i].second);
        }
        solver.setGuess(xp, guess);
      }
      ContinuationPoint p;
      p.value = U;
      try {
        p.result = solver.resolve(guess);
        p.converged = true;
      } catch (const Error& e) {
        p.failure = e.what();
      }
      pts.push_back(std::move(p));
    }
    return pts.front();
  };

  const double step = set.speed_step_m_s;
  double U = U0;
  while (U <= set.speed_max_m_s + 1e-12) {
    ContinuationPoint p = solveAt(U);
    if (!p.converged) {
      if (branch.empty())
        throw Error("constant radius R = " + formatValue(R) + " m on '" + v.name + "': no steady state at the first speed " +
                    formatValue(U) + " m/s: " + p.failure);
      out.limit_reason = p.failure;
      break;
    }
    out.points.push_back(measure(U, p.result));
    branch.emplace_back(U, std::move(p.result));
    U += step;
  }
  if (out.points.empty()) throw Error("constant radius: no point converged");
  out.limit_speed_m_s = out.points.back().speed_m_s;
  out.limit_lateral_accel_m_s2 = out.points.back().lateral_accel_m_s2;
  if (!out.limit_reason.empty()) {
    // The limit: the fold of the branch in speed (the largest speed on the
    // radius), by pseudo-arclength continuation from the last converged point,
    // located to limit_tolerance_m_s, and past_limit_points beyond it.
    ArclengthOptions o;
    o.step = 0.25 * step;
    o.max_step = step;
    o.min_step = o.location_tolerance = set.limit_tolerance_m_s;
    o.max_points = 200;
    o.stop_after_folds = 1;
    o.points_after_last_fold = set.past_limit_points;
    o.lambda_max = set.speed_max_m_s + step;
    o.lambda_min = 0.5 * U0;
    // The speed moves the rear angle of a speed-dependent strategy too.
    const auto drive = [&v](SimTK::State& s, double Ud) {
      v.speed->setSpeed(s, Ud);
      v.holdSteering(Ud, v.front->getHeldAngle());
    };
    const auto ta = clock::now();
    try {
      const ArclengthResult ar =
          continueSteadyState(solver, branch.back().second, branch.back().first, drive, step, set.stability, o);
      out.limit_steps = ar.steps;
      out.limit_rejected_steps = ar.rejected_steps;
      const ArclengthSpecialPoint* fold = nullptr;
      for (const auto& sp : ar.special)
        if (sp.kind == "fold" && !fold) fold = &sp;
      if (fold) {
        const ConstantRadiusPoint f = measure(fold->point.lambda, solver.makeDrivenResult(fold->point.x, fold->point.lambda));
        out.limit_found = true;
        out.limit_speed_m_s = f.speed_m_s;
        out.limit_lateral_accel_m_s2 = f.lateral_accel_m_s2;
        out.limit_front_rad = f.front_rad;
        out.limit_eigenvalues = fold->point.eigenvalues;
        out.limit_bracket_m_s = fold->bracket_length;
        for (const auto& q : ar.points)
          if (q.s > fold->point.s) out.past_limit_points.push_back(measure(q.lambda, solver.makeDrivenResult(q.x, q.lambda)));
      } else {
        out.limit_reason += "; pseudo-arclength continuation found no fold (stopped: " + ar.stop_reason + ")";
      }
    } catch (const Error& e) {
      out.limit_reason += "; pseudo-arclength continuation: " + std::string(e.what());
    }
    out.solve_wall_time_s += std::chrono::duration<double>(clock::now() - ta).count();
  }

  // Gradients along the sweep, d y / d a_y by three-point differences (non-
  // uniform central inside, one-sided second order at the first point, the
  // a_y -> 0 value): the understeer gradient (y = delta_f), the roll gradient
  // (y = roll) and the side-slip gradient (y = beta), ISO 4138's three.
  auto& P = out.points;
  const std::size_t n = P.size();
  auto gradient = [&](double ConstantRadiusPoint::*y, double ConstantRadiusPoint::*dy) -> double {
    for (std::size_t i = 0; i < n; ++i) {
      if (n < 2) break;
      std::size_t a = i == 0 ? 0 : i - 1, b = i == 0 ? 1 : (i + 1 < n ? i + 1 : i);
      if (i + 1 == n) a = i - 1, b = i;
      if (i > 0 && i + 1 < n) {
        const double x0 = P[i - 1].lateral_accel_m_s2, x1 = P[i].lateral_accel_m_s2, x2 = P[i + 1].lateral_accel_m_s2;
        const double y0 = P[i - 1].*y, y1 = P[i].*y, y2 = P[i + 1].*y;
        const double h0 = x1 - x0, h1 = x2 - x1;
        P[i].*dy = (-h1 / (h0 * (h0 + h1))) * y0 + ((h1 - h0) / (h0 * h1)) * y1 + (h0 / (h1 * (h0 + h1))) * y2;
      } else {
        P[i].*dy = (P[b].*y - P[a].*y) / (P[b].lateral_accel_m_s2 - P[a].lateral_accel_m_s2);
      }
    }
    if (n < 2) return 0;
    if (n >= 3) {
      const double x0 = P[0].lateral_accel_m_s2, x1 = P[1].lateral_accel_m_s2, x2 = P[2].lateral_accel_m_s2;
      const double h0 = x1 - x0, h1 = x2 - x1;
      P[0].*dy = -(2 * h0 + h1) / (h0 * (h0 + h1)) * P[0].*y + (h0 + h1) / (h0 * h1) * P[1].*y -
                 h0 / (h1 * (h0 + h1)) * P[2].*y;
    }
    return P[0].*dy;
  };
  out.understeer_gradient_linear_rad_per_m_s2 =
      gradient(&ConstantRadiusPoint::front_rad, &ConstantRadiusPoint::understeer_gradient_rad_per_m_s2);
  out.roll_gradient_linear_rad_per_m_s2 =
      gradient(&ConstantRadiusPoint::roll_rad, &ConstantRadiusPoint::roll_gradient_rad_per_m_s2);
  out.side_slip_gradient_linear_rad_per_m_s2 =
      gradient(&ConstantRadiusPoint::side_slip_rad, &ConstantRadiusPoint::side_slip_gradient_rad_per_m_s2);
  if (set.stability) {
    for (std::size_t i = 0; i < n; ++i) {
      if (P[i].stable) continue;
      if (i == 0) {
        out.stability_lost_speed_m_s = P[0].speed_m_s;
        out.stability_lost_lateral_accel_m_s2 = P[0].lateral_accel_m_s2;
      } else {
        const double a = P[i - 1].least_damped.real(), b = P[i].least_damped.real();
        const double w = b != a ? std::clamp((0 - a) / (b - a), 0.0, 1.0) : 1.0;
        out.stability_lost_speed_m_s = P[i - 1].speed_m_s + w * (P[i].speed_m_s - P[i - 1].speed_m_s);
        out.stability_lost_lateral_accel_m_s2 =
            P[i - 1].lateral_accel_m_s2 + w * (P[i].lateral_accel_m_s2 - P[i - 1].lateral_accel_m_s2);
      }
      break;
    }
  }
  out.wall_time_s = std::chrono::duration<double>(clock::now() - t0).count();
  return out;
}

}  // namespace vdyn
