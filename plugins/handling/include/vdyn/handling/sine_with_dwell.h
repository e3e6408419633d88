#pragma once
// Sine with dwell (FMVSS 126, S6-S7): the angle A that gives 0.3 g of steady
// lateral acceleration at 80 km/h (the regulation's slowly increasing steer
// reads it from a quasi-steady ramp; here its limit, the steady-state solve at
// that lateral acceleration), then a 0.7 Hz sine whose second peak is held for
// a 500 ms dwell, at amplitudes 1.5 A, 2 A, ... up to the largest of
// max_amplitude_factor A and max_amplitude_rad. Per run: the yaw-rate ratios
// at 1.0 s and 1.75 s after the completion of steer (COS) to the first yaw-rate
// peak after the steering changes sign, and the lateral displacement of the
// chassis origin 1.07 s after the beginning of steer (BOS), against the
// regulation's limits: <= 35 %, <= 20 %, >= 1.83 m (GVWR <= 3500 kg; required
// from 5 A). As the procedure: the speed is held (3.18) up to the beginning of
// steer and the vehicle coasts from there (`coast`, default true); the sine
// starts and ends with its full rate (no blend): the integrator restarts at
// both kinks (runHandlingTransient's restarts). A run whose vehicle does not
// recover (evaluateSineWithDwellRun) is reported as spun out, with no ratios,
// and fails the test.
#include <string>
#include <vector>

#include "vdyn/handling/handling.h"

namespace vdyn {

struct SineWithDwellSettings {
  /// Keys as the fields (speed_m_s, lateral_accel_m_s2, frequency_Hz, dwell_s,
  /// start_s, after_s, first_factor, factor_step, max_amplitude_factor,
  /// max_amplitude_rad, sample_s, coast, integrator), each optional:
  /// fields(), then validate().
  static SineWithDwellSettings fromParams(const ParamReader& r);
  /// The key table (reading, `vdyn list`).
  static const FieldTable<SineWithDwellSettings>& fields();

  double speed_m_s = 80.0 / 3.6;      ///< m/s (80 km/h)
  double lateral_accel_m_s2 = 0.3 * 9.81;  ///< a_y defining A, m/s^2 (0.3 g)
  double frequency_Hz = 0.7;
  double dwell_s = 0.5;
  double start_s = 0.5;               ///< beginning of steer (BOS), s
  double after_s = 2.5;               ///< simulated time after COS, s
  double first_factor = 1.5;          ///< first amplitude / A
  double factor_step = 0.5;           ///< increment of amplitude / A
  double max_amplitude_factor = 6.5;  ///< last amplitude / A (the regulation's 6.5 A or 270 deg at the wheel)
  double max_amplitude_rad = 0.35;    ///< cap on the road-wheel amplitude, rad
  double yaw_ratio_1s_limit = 0.35, yaw_ratio_175_limit = 0.20;  ///< 1
  double displacement_limit_m = 1.83;       ///< at 1.07 s after BOS, m
  double displacement_from_factor = 5.0;    ///< the displacement limit applies from this amplitude / A
  double sample_s = 0.002;
  /// Coast from the beginning of steer (the speed hold released); false =
  /// the speed held throughout (a deviation, for comparison).
  bool coast = true;
  IntegratorSettings integrator;
  SineWithDwellSettings() { integrator.accuracy = 1e-6; }
  void validate() const;
};

struct SineWithDwellRun {
  double factor = 0, amplitude_rad = 0;
  /// true: the metrics below are the run's; false: no number is reported
  /// (spun_out, or a failed run), `reason` says why.
  bool completed = false;
  /// The vehicle did not recover: its side slip passed the spin limit, or the
  /// yaw rate after the steering reversal had no peak before COS + 1.0 s, or
  /// with the steering centred (after COS) it grew beyond that peak, or grew
  /// again after COS + 1.75 s to end the run above half the peak.
  bool spun_out = false;
  std::string reason;
  /// First local peak of the yaw rate after the steering changes sign (the
  /// regulation's psi_dot_Peak; sign opposite to the first steer), rad/s, and its time, s.
  double peak_yaw_rate_rad_s = 0, peak_time_s = 0;
  double yaw_ratio_1s = 0, yaw_ratio_175 = 0;  ///< yaw rate at COS + 1.0 / 1.75 s over the peak, 1
  double lateral_displacement_m = 0;  ///< at BOS + 1.07 s, + toward the first steer
  bool pass = false;
  HandlingHistory history;
  RunSummary run;  ///< the integration's counts (steps, ...; a run that threw: zeros)
};

struct SineWithDwellResult {
  double angle_A_rad = 0;            ///< front angle at lateral_accel_m_s2 (steady state)
  std::vector<SineWithDwellRun> runs;
  bool pass = false;                 ///< every run completed and within the limits
};

/// The instants of one run, s: beginning of steer (BOS), the steering's sign
/// change (BOS + T/2) and the completion of steer (COS = BOS + T + dwell).
struct SineWithDwellTimes {
  double bos_s = 0, reversal_s = 0, cos_s = 0;
  double first_steer_sign = 1;  ///< sign of the first lobe's angle (+1: left first)
};

/// The metrics of one completed transient (FMVSS 126 S7.6-S7.7): finds the
/// first local yaw-rate peak after the reversal (the yaw rate moving away
/// from zero, then back by more than 1 % of the peak), the ratios at COS +
/// 1.0 / 1.75 s and the displacement; sets completed = false and spun_out =
/// true (no number) when there is no such peak before COS + 1.0 s or the yaw
/// rate exceeds it in magnitude after COS or grows again after COS + 1.75 s
/// to end above half of it, and completed = false when the yaw rate
/// never takes the reversal's sign. pass against the settings' limits.
/// The history must cover COS + 1.75 s.
void evaluateSineWithDwellRun(const HandlingHistory& history, const SineWithDwellTimes& times,
                              const SineWithDwellSettings& settings, SineWithDwellRun& run);

/// The angle A, rad: the front angle of the steady turn at speed_m_s with
/// lateral_accel_m_s2 (solveSteeringForLateralAcceleration).
double calcSineWithDwellAngle(const HandlingVehicle& vehicle, const SineWithDwellSettings& settings);
/// The amplitude factors run for an angle A: first_factor, + factor_step, ...
/// up to max_amplitude_factor, the last one the first whose amplitude reaches
/// max_amplitude_rad.
std::vector<double> calcSineWithDwellFactors(const SineWithDwellSettings& settings, double angle_A_rad);
/// One run at amplitude min(factor A, max_amplitude_rad). Sets the vehicle's
/// steering (its commands are the run's: one run at a time per vehicle).
SineWithDwellRun runSineWithDwellAmplitude(const HandlingVehicle& vehicle, const SineWithDwellSettings& settings,
                                           double angle_A_rad, double factor);

/// The whole test: A, then the amplitude runs, independent of each other, on
/// up to `threads` threads (runJobs, vdyn/core/sweep.h), each on its own
/// vehicle from `make`; the result does not depend on `threads`.
SineWithDwellResult runSineWithDwell(const HandlingVehicleMaker& make, const SineWithDwellSettings& settings,
                                     int threads = 1);

}  // namespace vdyn
