#include "vdyn/handling/sine_with_dwell.h"

#include <cmath>

#include "vdyn/core/interrupt.h"
#include "vdyn/core/sweep.h"

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

const FieldTable<SineWithDwellSettings>& SineWithDwellSettings::fields() {
  using S = SineWithDwellSettings;
  static const FieldTable<S> t = [] {
    FieldTable<S> f;
    addTransientTestKeys(f, "entry speed (80 km/h; held up to the beginning of steer)",
                         "steady lateral acceleration defining A (0.3 g)")
        .number("frequency_Hz", &S::frequency_Hz, "Hz", "sine frequency")
        .number("dwell_s", &S::dwell_s, "s", "dwell at the second peak")
        .number("start_s", &S::start_s, "s", "beginning of steer (BOS)")
        .number("after_s", &S::after_s, "s", "simulated time after the completion of steer (>= 1.75)")
        .number("first_factor", &S::first_factor, "", "first amplitude / A")
        .number("factor_step", &S::factor_step, "", "amplitude increment / A")
        .number("max_amplitude_factor", &S::max_amplitude_factor, "", "last amplitude / A")
        .number("max_amplitude_rad", &S::max_amplitude_rad, "rad", "cap on the road-wheel amplitude")
        .boolean("coast", &S::coast, "coast from the beginning of steer (false: speed held)");
    return f;
  }();
  return t;
}

SineWithDwellSettings SineWithDwellSettings::fromParams(const ParamReader& r) {
  SineWithDwellSettings s;
  fields().read(r, s);
  s.validate();
  return s;
}

void evaluateSineWithDwellRun(const HandlingHistory& h, const SineWithDwellTimes& tm, const SineWithDwellSettings& set,
                              SineWithDwellRun& run) {
  const std::vector<double>& t = h.t_s;
  const std::vector<double>& r = h.yaw_rate_rad_s;
  if (t.empty() || t.back() < tm.cos_s + 1.75 - 1e-9)
    throw Error("sine with dwell: the history ends at " + formatValue(t.empty() ? 0.0 : t.back()) +
                " s, before COS + 1.75 s = " + formatValue(tm.cos_s + 1.75) + " s");
  run.completed = false;
  run.spun_out = false;
  run.pass = false;
  const double sg = -tm.first_steer_sign;  // sign of the yaw rate the reversal produces
  const double tSample1 = tm.cos_s + 1.0, tSample175 = tm.cos_s + 1.75;
  // The first local peak of sg * r after the reversal: the largest value since
  // the last time the yaw rate turned toward sg, confirmed once it has fallen
  // back by 1 % of itself. An extreme at the anchor (the yaw rate already
  // retreating there: the first lobe's motion) is not a peak; the anchor moves on.
  std::size_t i = 0;
  while (i < t.size() && t[i] < tm.reversal_s) ++i;
  std::size_t anchor = i, im = i;
  bool found = false;
  for (; i < t.size() && t[i] <= tSample1; ++i) {
    const double y = sg * r[i];
    if (y > sg * r[im]) {
      im = i;
    } else if (sg * r[im] - y > 0.01 * std::abs(r[im]) + 1e-9) {
      if (im > anchor) {
        found = true;
        break;
      }
      anchor = im = i;
    }
  }
  if (!found) {
    run.spun_out = true;
    run.reason = "spun out: the yaw rate after the steering reversal has no peak up to COS + 1.0 s (" +
                 formatSig(interpolate(t, r, tSample1)) + " rad/s there, still growing)";
    return;
  }
  const double pk = r[im];
  if (!(sg * pk > 0)) {
    run.reason = "the yaw rate did not take the reversal's sign (its first peak after the reversal is " +
                 formatSig(pk) + " rad/s)";
    return;
  }
  // With the steering centred (from COS) a recovering vehicle's yaw rate
  // stays below that peak. (While steered, a saturated vehicle's yaw rate may
  // wiggle past its first peak: that is no spin.)
  for (std::size_t k = im + 1; k < t.size(); ++k)
    if (t[k] >= tm.cos_s && std::abs(r[k]) > std::abs(pk)) {
      run.spun_out = true;
      run.reason = "spun out: the yaw rate " + formatSig(r[k]) + " rad/s at t = " + formatSig(t[k]) +
                   " s exceeds its peak after the steering reversal (" + formatSig(pk) + " rad/s at " +
                   formatSig(t[im]) + " s)";
      return;
    }
  // Nor does it turn back into the spin: a yaw rate that grows again after the
  // second ratio sample and ends above half the peak (a slow spin that has not
  // passed the peak before the run ends).
  const double rS = interpolate(t, r, tSample175), rE = r.back();
  if (t.back() > tSample175 && sg * rE > sg * rS && sg * rE > 0.5 * std::abs(pk)) {
    run.spun_out = true;
    run.reason = "spun out: with the steering centred the yaw rate grows again, from " + formatSig(rS) +
                 " rad/s at COS + 1.75 s to " + formatSig(rE) + " rad/s at " + formatSig(t.back()) + " s (peak " +
                 formatSig(pk) + " rad/s)";
    return;
  }
  run.completed = true;
  run.peak_yaw_rate_rad_s = pk;
  run.peak_time_s = t[im];
  run.yaw_ratio_1s = interpolate(t, r, tSample1) / pk;
  run.yaw_ratio_175 = interpolate(t, r, tSample175) / pk;
  run.lateral_displacement_m =
      tm.first_steer_sign * (interpolate(t, h.y_m, tm.bos_s + 1.07) - interpolate(t, h.y_m, tm.bos_s));
  run.pass = run.yaw_ratio_1s <= set.yaw_ratio_1s_limit && run.yaw_ratio_175 <= set.yaw_ratio_175_limit &&
             (run.factor < set.displacement_from_factor - 1e-9 || run.lateral_displacement_m >= set.displacement_limit_m);
}

double calcSineWithDwellAngle(const HandlingVehicle& v, const SineWithDwellSettings& set) {
  set.validate();
  v.validate();
  return solveSteeringForLateralAcceleration(v, set.speed_m_s, set.lateral_accel_m_s2);
}

std::vector<double> calcSineWithDwellFactors(const SineWithDwellSettings& set, double angleA) {
  std::vector<double> k;
  for (double f = set.first_factor; f <= set.max_amplitude_factor + 1e-9; f += set.factor_step) {
    k.push_back(f);
    if (f * angleA >= set.max_amplitude_rad) break;
  }
  return k;
}

SineWithDwellRun runSineWithDwellAmplitude(const HandlingVehicle& v, const SineWithDwellSettings& set, double angleA,
                                           double k) {
  set.validate();
  v.validate();
  const double U = set.speed_m_s;
  const double w = 2 * SimTK::Pi * set.frequency_Hz, T = 1 / set.frequency_Hz, t0 = set.start_s, dw = set.dwell_s;
  const double tCos = t0 + T + dw;  // completion of steer
  SineWithDwellRun run;
  run.factor = k;
  run.amplitude_rad = std::min(k * angleA, set.max_amplitude_rad);
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
    // The criteria are the yaw rate's ratios and the lateral displacement: the
    // lateral acceleration (one more evaluation per sample) is not recorded.
    run.history = runHandlingTransient(v, U, tCos + set.after_s, set.sample_s, set.integrator, 0.5, &run.run,
                                       {t0, tCos}, set.coast ? t0 : 1e300, nullptr, false);
    run.completed = true;
  } catch (const Interrupted&) {
    throw;  // SIGINT/SIGTERM: not a spin-out
  } catch (const Error& e) {
    run.reason = e.what();
  }
  if (run.completed) {
    SineWithDwellTimes times;
    times.bos_s = t0, times.reversal_s = t0 + 0.5 * T, times.cos_s = tCos;
    times.first_steer_sign = A >= 0 ? 1 : -1;
    evaluateSineWithDwellRun(run.history, times, set, run);
  } else {
    run.spun_out = run.reason.find("spun out") != std::string::npos;
  }
  v.holdSteering(U, 0);
  return run;
}

SineWithDwellResult runSineWithDwell(const HandlingVehicleMaker& make, const SineWithDwellSettings& set, int threads) {
  set.validate();
  SineWithDwellResult out;
  out.angle_A_rad = calcSineWithDwellAngle(*make(), set);
  const std::vector<double> factors = calcSineWithDwellFactors(set, out.angle_A_rad);
  out.runs.resize(factors.size());
  runJobs(factors.size(), threads, [&](std::size_t i) {
    out.runs[i] = runSineWithDwellAmplitude(*make(), set, out.angle_A_rad, factors[i]);
  });
  out.pass = true;
  for (const auto& r : out.runs) out.pass = out.pass && r.pass;
  return out;
}

}  // namespace vdyn
