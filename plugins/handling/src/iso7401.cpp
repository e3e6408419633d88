#include "vdyn/handling/iso7401.h"

#include <chrono>
#include <cmath>
#include <limits>

#include <Eigen/Dense>

namespace vdyn {

namespace {
const double kPi = SimTK::Pi;
/// The seed's smooth step (7.4): s in [0, 1] -> 6 s^2 - 8 s^3 + 3 s^4 and its derivatives.
SteerCommandValue smoothStep(double t, double t0, double T, double D) {
  if (t <= t0) return {0, 0, 0};
  if (t >= t0 + T) return {D, 0, 0};
  const double s = (t - t0) / T;
  return {D * (6 * s * s - 8 * s * s * s + 3 * s * s * s * s), D * (12 * s - 24 * s * s + 12 * s * s * s) / T,
          D * (12 - 48 * s + 36 * s * s) / (T * T)};
}
/// First time y crosses `level` (upward for level > 0, downward for < 0) after t_from; NaN if never.
double crossing(const std::vector<double>& t, const std::vector<double>& y, double level, double tFrom) {
  for (std::size_t i = 1; i < t.size(); ++i) {
    if (t[i] < tFrom) continue;
    const bool a = level > 0 ? y[i - 1] < level : y[i - 1] > level;
    const bool b = level > 0 ? y[i] >= level : y[i] <= level;
    if (a && b) return t[i - 1] + (level - y[i - 1]) / (y[i] - y[i - 1]) * (t[i] - t[i - 1]);
  }
  return std::numeric_limits<double>::quiet_NaN();
}
struct PeakAt {
  double t, y;
};
PeakAt peak(const std::vector<double>& t, const std::vector<double>& y, double sign) {
  PeakAt p{t.front(), y.front()};
  for (std::size_t i = 0; i < t.size(); ++i)
    if (sign * y[i] > sign * p.y) p = {t[i], y[i]};
  return p;
}
}  // namespace

void StepSteerSettings::validate() const {
  requirePositive(speed_m_s, "step steer speed_m_s");
  requireFinite(lateral_accel_m_s2, "step steer lateral_accel_m_s2");
  if (lateral_accel_m_s2 == 0) throw Error("step steer lateral_accel_m_s2 must be non-zero");
  requireNonNegative(step_start_s, "step steer step_start_s");
  requirePositive(ramp_time_s, "step steer ramp_time_s");
  requirePositive(sample_s, "step steer sample_s");
  if (!(duration_s > 2 * ramp_time_s))
    throw Error("step steer duration_s (" + formatValue(duration_s) + ") must exceed twice ramp_time_s");
}

const FieldTable<StepSteerSettings>& StepSteerSettings::fields() {
  static const FieldTable<StepSteerSettings> t = [] {
    FieldTable<StepSteerSettings> f;
    addTransientTestKeys(f, "test speed (ISO 7401: 80 km/h)", "steady lateral acceleration the step aims at")
        .number("step_start_s", &StepSteerSettings::step_start_s, "s", "start of the steering ramp")
        .number("ramp_time_s", &StepSteerSettings::ramp_time_s, "s", "ramp duration (smooth step 7.4)")
        .number("duration_s", &StepSteerSettings::duration_s, "s", "simulated time after the ramp starts");
    return f;
  }();
  return t;
}

StepSteerSettings StepSteerSettings::fromParams(const ParamReader& r) {
  StepSteerSettings s;
  fields().read(r, s);
  s.validate();
  return s;
}

StepSteerResult runStepSteer(const HandlingVehicle& v, const StepSteerSettings& set) {
  set.validate();
  v.validate();
  StepSteerResult out;
  const double U = set.speed_m_s;
  SteadyStateResult ss;
  out.front_rad = solveSteeringForLateralAcceleration(v, U, set.lateral_accel_m_s2, &ss);
  out.rear_rad = v.rearAngle(U, out.front_rad);
  const SimTK::MobilizedBody ch = v.scene->getBody(v.chassis_body);
  v.scene->getSystem().realize(ss.state, SimTK::Stage::Velocity);
  out.steady_yaw_rate_rad_s = ch.getBodyAngularVelocity(ss.state)[2];
  out.steady_lateral_accel_m_s2 = calcSteadyLateralAcceleration(ch, ss.state);
  out.yaw_rate_gain_1_per_s = out.steady_yaw_rate_rad_s / out.front_rad;
  out.lateral_accel_gain_m_s2_per_rad = out.steady_lateral_accel_m_s2 / out.front_rad;

  const double t0 = set.step_start_s, T = set.ramp_time_s, D = out.front_rad;
  v.setSteering(U, [t0, T, D](double t) { return smoothStep(t, t0, T, D); });
  // The time (7.4) passes 50 % of the step (bisection on s).
  double lo = 0, hi = 1;
  for (int i = 0; i < 60; ++i) {
    const double m = 0.5 * (lo + hi);
    (6 * m * m - 8 * m * m * m + 3 * m * m * m * m < 0.5 ? lo : hi) = m;
  }
  out.t50_s = t0 + 0.5 * (lo + hi) * T;
  out.history = runHandlingTransient(v, U, t0 + set.duration_s, set.sample_s, set.integrator, 0.5, &out.run);
  const auto& h = out.history;
  const double sg = out.steady_yaw_rate_rad_s > 0 ? 1 : -1;
  const double t90 = crossing(h.t_s, h.yaw_rate_rad_s, 0.9 * out.steady_yaw_rate_rad_s, t0);
  if (!std::isfinite(t90))
    throw Error("step steer of '" + v.name + "': the yaw rate never reached 90 % of its steady value " +
                formatValue(out.steady_yaw_rate_rad_s) + " rad/s");
  out.yaw_response_time_s = t90 - out.t50_s;
  const PeakAt pr = peak(h.t_s, h.yaw_rate_rad_s, sg);
  // A response that rises to its steady value without a peak has its largest
  // value at the end of the run: no peak response time, no overshoot.
  const bool rising = pr.t >= h.t_s.back() - 0.1 * set.duration_s;
  out.yaw_peak_response_time_s = rising ? std::numeric_limits<double>::quiet_NaN() : pr.t - out.t50_s;
  out.yaw_overshoot = rising ? 0.0 : (pr.y - out.steady_yaw_rate_rad_s) / out.steady_yaw_rate_rad_s;
  const double a90 = crossing(h.t_s, h.lateral_accel_m_s2, 0.9 * out.steady_lateral_accel_m_s2, t0);
  out.lateral_accel_response_time_s = a90 - out.t50_s;
  const PeakAt pa = peak(h.t_s, h.lateral_accel_m_s2, sg);
  const bool risingA = pa.t >= h.t_s.back() - 0.1 * set.duration_s;
  out.lateral_accel_peak_response_time_s = risingA ? std::numeric_limits<double>::quiet_NaN() : pa.t - out.t50_s;
  out.lateral_accel_overshoot = risingA ? 0.0 : (pa.y - out.steady_lateral_accel_m_s2) / out.steady_lateral_accel_m_s2;
  out.final_yaw_rate_rad_s = h.yaw_rate_rad_s.back();
  v.holdSteering(U, 0);
  return out;
}

std::vector<double> logFrequencies(double f0, double f1, int n) {
  requirePositive(f0, "frequency start");
  if (!(f1 > f0) || n < 2) throw Error("frequency range: need f1 > f0 and n >= 2");
  std::vector<double> f;
  for (int i = 0; i < n; ++i) f.push_back(f0 * std::pow(f1 / f0, double(i) / (n - 1)));
  return f;
}

FrequencyResponseResult calcSteeringFrequencyResponse(const HandlingVehicle& v, double U,
                                                      const std::vector<double>& freqs, double ayOp) {
  const auto t0 = std::chrono::steady_clock::now();
  v.validate();
  requirePositive(U, "frequency response speed_m_s");
  requireFinite(ayOp, "frequency response lateral_accel_m_s2");
  for (double f : freqs) requirePositive(f, "frequency response frequency_Hz");
  const Scene& sc = *v.scene;
  // The operating point: straight running at U (steering at zero) or the
  // steady turn at a_y (front angle solved).
  SimTK::State start = v.make_initial_state(U);
  double d0 = 0;
  if (ayOp != 0) {
    SteadyStateResult turn;
    d0 = solveSteeringForLateralAcceleration(v, U, ayOp, &turn);
    start = turn.state;
  }
  v.holdSteering(U, d0);
  SteadyStateSolver solver(sc, makeSteadyTurningProblem(sc, v.chassis_body, v.wheel_bodies, 0.0));
  const SteadyStateResult ss = solver.solve(start);
  const HandlingVehicle* vp = &v;
  LinearInput in;
  in.name = "front steering angle (rad)";
  in.typical = 0.01;
  in.set = [vp, U, d0](SimTK::State&, double dv, double dd, double ddd) {
    const double d = d0 + dv;
    vp->front->setValue({d, dd, ddd});
    if (vp->rear) {
      if (vp->rear_strategy) {
        const RearSteerTarget r = vp->rear_strategy->calcTarget(U, d, dd, ddd);
        vp->rear->setValue({r.angle_rad, r.rate_rad_s, r.accel_rad_s2});
      } else {
        vp->rear->setHold(0);
      }
    }
  };
  const SimTK::MobilizedBody ch = sc.getBody(v.chassis_body);
  LinearOutput yaw{"yaw rate (rad/s)", [ch](const SimTK::State& s) { return ch.getBodyAngularVelocity(s)[2]; }};
  LinearOutput ay{"lateral acceleration (m/s^2)", [ch](const SimTK::State& s) {
                    return ch.getBodyOriginAcceleration(s)[1];  // zero yaw: ground y is the left of the heading
                  }};
  const LinearModel lin = solver.calcLinearModel(ss, {in}, {yaw, ay});
  v.holdSteering(U, 0);
  FrequencyResponseResult out;
  out.speed_m_s = U;
  out.dimension = int(lin.A.rows());
  Eigen::EigenSolver<Eigen::MatrixXd> es(lin.A, false);
  double maxRe = -1e300;
  for (int i = 0; i < lin.A.rows(); ++i) maxRe = std::max(maxRe, es.eigenvalues()[i].real());
  out.stable = maxRe < -1e-6;
  out.yaw_gain_zero_1_per_s = std::abs(lin.calcResponse(1e-9)(0, 0));
  for (double f : freqs) {
    const Eigen::MatrixXcd G = lin.calcResponse(2 * kPi * f);
    FrequencyResponsePoint p;
    p.frequency_Hz = f;
    p.yaw_gain_1_per_s = std::abs(G(0, 0));
    p.yaw_phase_deg = std::arg(G(0, 0)) * 180 / kPi;
    p.ay_gain_m_s2_per_rad = std::abs(G(1, 0));
    p.ay_phase_deg = std::arg(G(1, 0)) * 180 / kPi;
    out.points.push_back(p);
  }
  // ISO 7401's named figures of the frequency response, from the same linear model.
  const Eigen::MatrixXcd G1 = lin.calcResponse(2 * kPi * 1.0);
  out.yaw_phase_1Hz_deg = std::arg(G1(0, 0)) * 180 / kPi;
  out.ay_phase_1Hz_deg = std::arg(G1(1, 0)) * 180 / kPi;
  out.ay_gain_zero_m_s2_per_rad = std::abs(lin.calcResponse(1e-9)(1, 0));
  out.ay_gain_ratio_1Hz = std::abs(G1(1, 0)) / out.ay_gain_zero_m_s2_per_rad;
  // Yaw-rate resonance: the largest |r / delta| over 0.01-10 Hz (a log scan of
  // 400 points, then golden-section search in log f to 1e-9 relative); none
  // when the largest is at the lowest frequency (no peak: the gain falls).
  auto gain = [&](double f) { return std::abs(lin.calcResponse(2 * kPi * f)(0, 0)); };
  const std::vector<double> scan = logFrequencies(0.01, 10.0, 400);
  std::size_t k = 0;
  for (std::size_t i = 1; i < scan.size(); ++i)
    if (gain(scan[i]) > gain(scan[k])) k = i;
  if (k > 0 && k + 1 < scan.size()) {
    double a = std::log(scan[k - 1]), b = std::log(scan[k + 1]);
    const double g = 0.5 * (std::sqrt(5.0) - 1);
    double c = b - g * (b - a), d = a + g * (b - a);
    while (b - a > 1e-9) {
      if (gain(std::exp(c)) > gain(std::exp(d))) b = d; else a = c;
      c = b - g * (b - a), d = a + g * (b - a);
    }
    out.yaw_resonance_frequency_Hz = std::exp(0.5 * (a + b));
    out.yaw_peak_ratio = gain(out.yaw_resonance_frequency_Hz) / out.yaw_gain_zero_1_per_s;
  }
  out.wall_time_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return out;
}

SineSteerResult runSineSteer(const HandlingVehicle& v, double U, double f, double A, const IntegratorSettings& integ,
                             double rampPeriods, double settle, int fitPeriods, double ay) {
  requirePositive(f, "sine steer frequency_Hz");
  requirePositive(A, "sine steer amplitude_rad");
  requirePositive(rampPeriods, "sine steer ramp_periods");
  requireNonNegative(settle, "sine steer settle_s");
  requireFinite(ay, "sine steer lateral_accel_m_s2");
  if (fitPeriods < 1) throw Error("sine steer fit_periods must be >= 1");
  double d0 = 0;
  SteadyStateResult turn;
  if (ay != 0) {
    d0 = solveSteeringForLateralAcceleration(v, U, ay, &turn);
    v.scene->getSystem().realize(turn.state, SimTK::Stage::Velocity);
  }
  const double w = 2 * kPi * f, Tr = rampPeriods / f;
  v.setSteering(U, [A, w, Tr, d0](double t) {
    double r = 1, rd = 0, rdd = 0;
    if (t < Tr) {
      const double s = std::max(t, 0.0) / Tr;
      r = 3 * s * s - 2 * s * s * s;
      rd = (6 * s - 6 * s * s) / Tr;
      rdd = (6 - 12 * s) / (Tr * Tr);
    }
    const double sn = std::sin(w * t), cs = std::cos(w * t);
    return SteerCommandValue{d0 + A * r * sn, A * (rd * sn + r * w * cs), A * (rdd * sn + 2 * rd * w * cs - r * w * w * sn)};
  });
  const double tFit0 = Tr + settle, tEnd = tFit0 + fitPeriods / f;
  SineSteerResult out;
  out.frequency_Hz = f;
  const double sample = 1.0 / (f * 200);
  const HandlingHistory h =
      runHandlingTransient(v, U, tEnd, sample, integ, 0.5, &out.run, {}, 1e300, ay != 0 ? &turn.state : nullptr);
  v.holdSteering(U, 0);
  // Least squares y = a sin(wt) + b cos(wt) + c over the fit window.
  std::vector<std::size_t> idx;
  for (std::size_t i = 0; i < h.t_s.size(); ++i)
    if (h.t_s[i] >= tFit0 - 1e-12) idx.push_back(i);
  Eigen::MatrixXd M(idx.size(), 3);
  Eigen::VectorXd yr(idx.size()), ya(idx.size());
  for (std::size_t k = 0; k < idx.size(); ++k) {
    const double t = h.t_s[idx[k]];
    M(k, 0) = std::sin(w * t);
    M(k, 1) = std::cos(w * t);
    M(k, 2) = 1;
    yr[k] = h.yaw_rate_rad_s[idx[k]];
    ya[k] = h.lateral_accel_m_s2[idx[k]];
  }
  const auto qr = M.colPivHouseholderQr();
  const Eigen::Vector3d cr = qr.solve(yr), ca = qr.solve(ya);
  // a sin + b cos = |G| A sin(wt + phi): |G| = hypot(a, b) / A, phi = atan2(b, a).
  out.yaw_gain_1_per_s = std::hypot(cr[0], cr[1]) / A;
  out.yaw_phase_deg = std::atan2(cr[1], cr[0]) * 180 / kPi;
  out.ay_gain_m_s2_per_rad = std::hypot(ca[0], ca[1]) / A;
  out.ay_phase_deg = std::atan2(ca[1], ca[0]) * 180 / kPi;
  out.fit_residual = (M * cr - yr).norm() / std::sqrt(double(idx.size())) / std::hypot(cr[0], cr[1]);
  return out;
}

}  // namespace vdyn
