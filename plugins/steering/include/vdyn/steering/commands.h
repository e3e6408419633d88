#pragma once
// Steering commands as time functions (family "steering_command"): the
// waveforms of the handling tests and measured manoeuvres, beside hold,
// smooth_step and steps (steering.h). Each gives the angle, its rate and its
// acceleration in closed form (the steering constraint (A.3)-(A.4) carries the
// acceleration); angles in rad, + left; times in s.
//
//   ramp             angle from initial_rad at rate_rad_s to final_rad, the
//                    rate blended in and out over blend_s by the cubic
//                    smoothstep h(u) = 3u^2 - 2u^3 (rate C1, angle C2);
//   sine             offset_rad + A e(t) sin(2 pi f (t - t0)) over `cycles`
//                    periods, e the envelope rising over fade_cycles periods
//                    at the start and falling over as many at the end by the
//                    same smoothstep (fade_cycles 0: e = 1, the rate jumps by
//                    2 pi f A at the start and the end);
//   chirp            offset_rad + A e(t) sin(phi), phi = 2 pi (f0 tau + (f1 -
//                    f0) tau^2 / (2 T)), tau = t - t0 in [0, T] (linear sweep of
//                    frequency f0 -> f1), envelope over fade_s at both ends;
//   sine_with_dwell  NHTSA FMVSS 126's steering input: A sin(2 pi f tau) up to
//                    its third quarter-period peak, held (the dwell) for
//                    dwell_s, then the last quarter period back to zero (the
//                    rate jumps by 2 pi f A at the start and the end, as the
//                    standard's);
//   table            a measured manoeuvre: a CSV file with columns time_s and
//                    angle_rad (ascending times, at least 2 rows), interpolated
//                    "cubic" (a cubic spline clamped to zero rate at the
//                    first and last rows, as a manoeuvre that starts and ends
//                    at rest: angle, rate and acceleration continuous) or
//                    "linear" (rate piecewise constant, acceleration 0: the
//                    rate jumps at every row), the first / last value held
//                    outside the table.
// Where a command's rate jumps (getRateJumpTimes), a transient analysis
// restarts its integrator (SimulationSettings::restart_times_s), the value
// taken from the right.
#include "vdyn/core/registry.h"

namespace vdyn {

/// Registers ramp, sine, chirp, sine_with_dwell and table (registerSteeringCommands calls it).
void registerWaveformCommands(PluginRegistry& registry);

}  // namespace vdyn
