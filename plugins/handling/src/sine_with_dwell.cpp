#include "vdyn/handling/sine_with_dwell.h"

#include <cmath>

namespace vdyn {

void SineWithDwellSettings::validate() const {
  requirePositive(speed_m_s, "sine with dwell speed_m_s");
  requirePositive(lateral_accel_m_s2, "sine with dwell lateral_accel_m_s2");
  requirePositive(frequency_Hz, "sine with dwell frequency_Hz");
  requireNonNegative(dwell_s, "sine with dwell dwell_s");
  requireNonNegative(start_s, "sine with dwell start_s");
  requirePositive(after_s, "sine with dwell after_s");
  if (after_s < 1.75) throw Error("sine with dwell after_s must be >= 1.75 s (the second ratio), got " + formatValue(after_s));
  requirePositive(first_factor, "sine with dwell first_factor");
  requirePositive(factor_step, "sine with dwell factor_step");
  requirePositive(max_amplitude_rad, "sine with dwell max_amplitude_rad");
  requirePositive(sample_s, "sine with dwell sample_s");
}

SineWithDwellSettings SineWithDwellSettings::fromParams(const ParamReader& r) {
  SineWithDwellSettings s;
  s.speed_m_s = r.numberOr("speed_m_s", s.speed_m_s);
  s.lateral_accel_m_s2 = r.numberOr("lateral_accel_m_s2", s.lateral_accel_m_s2);
  s.frequency_Hz = r.numberOr("frequency_Hz", s.frequency_Hz);
  s.dwell_s = r.numberOr("dwell_s", s.dwell_s);
  s.start_s = r.numberOr("start_s", s.start_s);
  s.after_s = r.numberOr("after_s", s.after_s);
  s.first_factor = r.numberOr("first_factor", s.first_factor);
  s.factor_step = r.numberOr("factor_step", s.factor_step);
  s.max_amplitude_factor = r.numberOr("max_amplitude_factor", s.max_amplitude_factor);
  s.max_amplitude_rad = r.numberOr("max_amplitude_rad", s.max_amplitude_rad);
  s.sample_s = r.numberOr("sample_s", s.sample_s);
  s.coast = r.booleanOr("coast", s.coast);
  if (r.has("integrator")) s.integrator = IntegratorSettings::fromParams(r.child("integrator"));
  s.validate();
  return s;
}

SineWithDwellResult runSineWithDwell(const HandlingVehicle& v, const SineWithDwellSettings& set) {
  set.validate();
  v.validate();
  SineWithDwellResult out;
  const double U = set.speed_m_s;
  out.angle_A_rad = solveSteeringForLateralAcceleration(v, U, set.lateral_accel_m_s2);
  const double w = 2 * SimTK::Pi * set.frequency_Hz, T = 1 / set.frequency_Hz, t0 = set.start_s, dw = set.dwell_s;
  const double tCos = t0 + T + dw;  // completion of steer
  out.pass = true;
  for (double k = set.first_factor; k <= set.max_amplitude_factor + 1e-9; k += set.factor_step) {
    SineWithDwellRun run;
    run.factor = k;
    run.amplitude_rad = std::min(k * out.angle_A_rad, set.max_amplitude_rad);
    const double A = run.amplitude_rad;
    // delta = A sin(w tau) up to 3/4 period, held at -A for the dwell, then the
    // last quarter; zero before BOS and from COS on. The rate jumps (0 <-> A w)
    // at BOS and COS: the run restarts there, the command taken from the right.
    const double tEndSteer = T + dw;
    v.setSteering(U, [A, w, T, t0, dw, tEndSteer](double t) {
      const double tau = t - t0;
      if (tau < 0 || tau >= tEndSteer) return SteerCommandValue{0, 0, 0};
      if (tau >= 0.75 * T && tau < 0.75 * T + dw) return SteerCommandValue{-A, 0, 0};
      const double x = tau >= 0.75 * T + dw ? tau - dw : tau;
      return SteerCommandValue{A * std::sin(w * x), A * w * std::cos(w * x), -A * w * w * std::sin(w * x)};
    });
    try {
      run.history = runHandlingTransient(v, U, tCos + set.after_s, set.sample_s, set.integrator, 0.5, nullptr,
                                         {t0, tCos}, set.coast ? t0 : 1e300);
      run.completed = true;
    } catch (const Error& e) {
      run.reason = e.what();
    }
    if (run.completed) {
      const auto& h = run.history;
      // First yaw-rate peak after the steering changes sign (t0 + T/2): the
      // extreme of the negative lobe up to COS + 1 s.
      double pk = 0;
      for (std::size_t i = 0; i < h.t_s.size(); ++i)
        if (h.t_s[i] >= t0 + 0.5 * T && h.t_s[i] <= tCos + 1.0) pk = std::min(pk, h.yaw_rate_rad_s[i]);
      run.peak_yaw_rate_rad_s = pk;
      const double r1 = interpolate(h.t_s, h.yaw_rate_rad_s, tCos + 1.0);
      const double r175 = interpolate(h.t_s, h.yaw_rate_rad_s, tCos + 1.75);
      run.yaw_ratio_1s = pk != 0 ? r1 / pk : 0;
      run.yaw_ratio_175 = pk != 0 ? r175 / pk : 0;
      run.lateral_displacement_m =
          interpolate(h.t_s, h.y_m, t0 + 1.07) - interpolate(h.t_s, h.y_m, t0);
      run.pass = run.yaw_ratio_1s <= set.yaw_ratio_1s_limit && run.yaw_ratio_175 <= set.yaw_ratio_175_limit &&
                 (k < set.displacement_from_factor - 1e-9 || run.lateral_displacement_m >= set.displacement_limit_m);
    }
    out.pass = out.pass && run.pass;
    out.runs.push_back(std::move(run));
    if (k * out.angle_A_rad >= set.max_amplitude_rad) break;
  }
  v.holdSteering(U, 0);
  return out;
}

}  // namespace vdyn
