#pragma once
// ISO 7401 lateral transient response: the step steer by simulation and the
// frequency response of yaw rate and lateral acceleration to the front
// steering angle from the linearisation about straight running
// (SteadyStateSolver::calcLinearModel with the steering command as input),
// and a sine-steer simulation to cross-check one frequency.
#include <limits>
#include <vector>

#include "vdyn/handling/handling.h"

namespace vdyn {

struct StepSteerSettings {
  /// Keys speed_m_s, lateral_accel_m_s2, step_start_s, ramp_time_s,
  /// duration_s, sample_s, integrator {method, accuracy, ...} (all optional):
  /// fields(), then validate().
  static StepSteerSettings fromParams(const ParamReader& r);
  /// The key table (reading, `vdyn list`).
  static const FieldTable<StepSteerSettings>& fields();

  double speed_m_s = 80.0 / 3.6;      ///< test speed, m/s (ISO 7401: 80 km/h)
  double lateral_accel_m_s2 = 4.0;    ///< steady a_y the step aims at, m/s^2 (ISO: 4)
  double step_start_s = 0.5;          ///< start of the steering ramp, s
  /// Ramp duration, s: the seed's smooth step (7.4) from 0 to the angle (ISO:
  /// 0.05-0.15 s from 10 % to 90 %).
  double ramp_time_s = 0.15;
  double duration_s = 4.0;            ///< simulated time after the ramp starts, s
  double sample_s = 0.002;            ///< sampling of the response, s
  IntegratorSettings integrator;      ///< default rk_merson at 1e-6
  StepSteerSettings() { integrator.accuracy = 1e-6; }
  void validate() const;
};

struct StepSteerResult {
  double front_rad = 0, rear_rad = 0;   ///< final road-wheel angles, rad
  double steady_yaw_rate_rad_s = 0;     ///< from the steady-state solver at the final angle
  double steady_lateral_accel_m_s2 = 0; ///< U_h r there
  double yaw_rate_gain_1_per_s = 0;     ///< steady r / delta_f, 1/s
  double lateral_accel_gain_m_s2_per_rad = 0;
  double t50_s = 0;                     ///< time the front angle passes 50 % of its step, s
  double yaw_response_time_s = 0;       ///< from t50 to 90 % of the steady yaw rate, s
  /// From t50 to the yaw-rate peak, s; NaN when the response rises to its
  /// steady value without a peak (largest value in the run's last 10 %).
  double yaw_peak_response_time_s = 0;
  double yaw_overshoot = 0;             ///< (peak - steady) / steady, 1 (0 without a peak)
  double lateral_accel_response_time_s = 0, lateral_accel_peak_response_time_s = 0, lateral_accel_overshoot = 0;
  double final_yaw_rate_rad_s = 0;      ///< simulation's last sample (settling check)
  HandlingHistory history;
  RunSummary run;
};

/// Step steer: the front angle giving the steady a_y (solved), applied by a
/// ramp from straight running at the test speed; metrics from the sampled
/// response against the steady state. Throws Error on a spin-out or a failed run.
StepSteerResult runStepSteer(const HandlingVehicle& vehicle, const StepSteerSettings& settings);

struct FrequencyResponsePoint {
  double frequency_Hz = 0;
  double yaw_gain_1_per_s = 0, yaw_phase_deg = 0;             ///< r / delta_f
  double ay_gain_m_s2_per_rad = 0, ay_phase_deg = 0;          ///< a_y / delta_f
};

struct FrequencyResponseResult {
  double speed_m_s = 0;
  std::vector<FrequencyResponsePoint> points;
  double yaw_gain_zero_1_per_s = 0;   ///< |G(0)| of the yaw rate (the steady gain), 1/s
  double ay_gain_zero_m_s2_per_rad = 0;  ///< |G(0)| of the lateral acceleration, m/s^2 per rad
  // ISO 7401's named figures (same linear model):
  double yaw_phase_1Hz_deg = 0;       ///< phase of r / delta_f at 1 Hz, deg (< 0: lag)
  double ay_phase_1Hz_deg = 0;        ///< phase of a_y / delta_f at 1 Hz, deg
  double ay_gain_ratio_1Hz = 0;       ///< |a_y / delta_f| at 1 Hz over its steady value
  /// Frequency of the largest |r / delta_f| in 0.01-10 Hz, Hz; NaN when the
  /// gain only falls from its steady value (no resonance).
  double yaw_resonance_frequency_Hz = std::numeric_limits<double>::quiet_NaN();
  double yaw_peak_ratio = std::numeric_limits<double>::quiet_NaN();  ///< the peak gain over the steady gain
  int dimension = 0;                  ///< independent states of the linear model
  bool stable = false;
  double wall_time_s = 0;
};

/// Frequency response about straight running at U (front angle 0), or about
/// the steady turn at U with lateral acceleration `lateral_accel_m_s2` (its
/// front angle solved), from the linearised equations of motion;
/// `frequencies_Hz` ascending, > 0. About a turn the tires work away from zero
/// slip, where a tire law with a kink there (the Gim tire's |alpha|) is smooth
/// and the small-signal theory holds.
FrequencyResponseResult calcSteeringFrequencyResponse(const HandlingVehicle& vehicle, double speed_m_s,
                                                      const std::vector<double>& frequencies_Hz,
                                                      double lateral_accel_m_s2 = 0);

/// Log-spaced frequencies from f0 to f1 (n >= 2 points), Hz.
std::vector<double> logFrequencies(double f0_Hz, double f1_Hz, int n);

struct SineSteerResult {
  double frequency_Hz = 0;
  double yaw_gain_1_per_s = 0, yaw_phase_deg = 0, ay_gain_m_s2_per_rad = 0, ay_phase_deg = 0;
  double fit_residual = 0;   ///< RMS of the yaw-rate fit residual over its amplitude, 1
  RunSummary run;
};

/// Sine steer delta_f = A w(t) sin(2 pi f t) from straight running at U, w a
/// smooth ramp 0 -> 1 over `ramp_periods`; gain and phase of the yaw rate and
/// a_y by a least-squares fit (sine, cosine, constant) over `fit_periods`
/// periods after `settle_s` more seconds.
/// With lateral_accel_m_s2 != 0 the sine is added to the front angle of that
/// steady turn and the run starts from the turn's steady state.
SineSteerResult runSineSteer(const HandlingVehicle& vehicle, double speed_m_s, double frequency_Hz,
                             double amplitude_rad, const IntegratorSettings& integrator, double ramp_periods = 1,
                             double settle_s = 2.0, int fit_periods = 2, double lateral_accel_m_s2 = 0);

}  // namespace vdyn
