#pragma once
// ISO 3888-2 (obstacle avoidance, the "moose test" double lane change): the
// cone layout computed from the vehicle width, the closed-loop run of a scene
// through it (the scene's path controller follows the lane centres), the cone
// strikes of the vehicle body and the highest entry speed that passes, found
// by bisection.
//
// Layout (ISO 3888-2:2011, clause 4.1 and Table 1; b = vehicle width, m; the
// table, its sources and what was checked against them: docs/iso3888_2_layout.md),
// along the ground X axis from the entry of section 1 at X1 (lane limits are
// the lines tangent to the cones' bases, clause 4.2):
//   section 1  entry lane     length 12   m, width 1.1 b + 0.25
//   section 2  transition     length 13.5 m (no cones beside it)
//   section 3  side lane      length 11   m, width b + 1, shifted to the LEFT:
//              its right cone line 1 m left of section 1's left cone line
//   section 4  transition     length 12.5 m
//   section 5  exit lane      length 12   m, width 1.3 b + 0.25, at least 3 m
//              (3 m for b < 2.115 m); its right cone line on section 1's right one
// 61 m in all (clause 4.1). Y = 0 is section 1's centre line (the vehicle starts on it).
//
// Cone strikes: each lane section's two cone lines are segments
// [X_start, X_end] at constant Y. The vehicle body is the rectangle
// [rear_x, front_x] x [-b/2, b/2] in the chassis frame, placed in the ground
// plane by the chassis position and yaw (roll and pitch are not projected: the
// cones are low and the body's roll moves its lower corners little). A cone
// line is struck when, at a recorded sample, the rectangle meets its segment
// or a body corner beside the lane lies beyond it (a body that passes a lane
// outside its cones, or crosses a line between two samples; samples every
// sample_s: at 25 m/s and 5 ms the body moves 0.125 m between samples). The run passes when no line is struck, the vehicle leaves section
// 5 and the run did not fail (spin-out, path lost, integrator failure).
//
// Deviations from the standard (stated): a path controller, not a driver,
// steers (the scene's path_control plugin; its reference is a line through the
// lanes with the seed's lane change (7.7) over each transition, extended by
// `transition_extension_m` into the lanes on either side: a stated choice of
// line, on which the highest passing speed depends); the
// speed is whatever the scene does (coasting from the entry speed when the
// scene has no speed hold, as the standard's released throttle; held when the
// scene names a speed-hold plugin in `speed_hold`).
#include <cmath>
#include <string>
#include <vector>

#include "vdyn/core/fields.h"
#include "vdyn/core/params.h"
#include "vdyn/core/scene_file.h"
#include "vdyn/core/simulation.h"
#include "vdyn/path/path.h"

namespace vdyn {

class AnimationRecorder;

/// One lane section with cones: [x_start, x_end] between cone lines at y_right < y_left.
struct ConeLane {
  int section = 0;            ///< 1, 3 or 5
  double x_start_m = 0, x_end_m = 0;
  double y_right_m = 0, y_left_m = 0;
  double width() const { return y_left_m - y_right_m; }
  double centre() const { return 0.5 * (y_left_m + y_right_m); }
};

struct Iso3888Layout {
  double vehicle_width_m = 0;          ///< b, m
  double entry_x_m = 0;                ///< X1, the entry of section 1, m
  double section_length_m[5] = {12.0, 13.5, 11.0, 12.5, 12.0};
  std::vector<ConeLane> lanes;         ///< sections 1, 3, 5
  double endX() const;                 ///< exit of section 5, m
  /// The standard layout for a vehicle of width b (> 0, m) entering at X1.
  static Iso3888Layout make(double vehicle_width_m, double entry_x_m);
  /// Reference path of the tracked point: a double lane change (7.7) over
  /// each transition section, extended by `extension_m` (>= 0) into the lanes
  /// before and after it, between lateral positions in lanes 1, 3 and 5 that
  /// are the lane centres (clearance_m < 0), or else the "inside" line a
  /// driver takes: in lanes 1 and 5 the body's left side and in lane 3 its
  /// right side `clearance_m` from the cone line (the smallest shifts; a lane
  /// narrower than b + 2 clearance_m gets its centre).
  DoubleLaneChangeParams makeReferencePath(double extension_m, double clearance_m) const;
};

/// The body outline in the chassis frame (x forward, y left), m.
struct BodyOutline {
  double front_x_m = 0, rear_x_m = 0;  ///< front_x > rear_x
  double half_width_m = 0;             ///< b / 2
  /// Corners in the ground plane for a chassis at (x, y) with yaw psi:
  /// front-left, front-right, rear-right, rear-left.
  std::vector<SimTK::Vec2> corners(double x_m, double y_m, double yaw_rad) const;
};

/// One cone line struck: lane section, side and the first time.
struct ConeStrike {
  int section = 0;
  std::string side;        ///< "left" or "right"
  double t_s = 0, x_m = 0; ///< time and chassis X of the first contact
};

struct ConeCheck {
  std::vector<ConeStrike> strikes;   ///< each struck cone line once
  /// Smallest clearance of a body corner to a cone line while the corner is
  /// beside its lane, m (< 0: a corner beyond the line).
  double min_clearance_m = 1e300;
  int min_clearance_section = 0;
  bool reached_exit = false;         ///< the body's rear passed section 5's end
};

/// Checks a sampled chassis motion (t, x, y, yaw) against the layout.
ConeCheck checkCones(const Iso3888Layout& layout, const BodyOutline& body, const std::vector<double>& t_s,
                     const std::vector<double>& x_m, const std::vector<double>& y_m,
                     const std::vector<double>& yaw_rad);

struct Iso3888Settings {
  /// Keys as the fields (all optional): vehicle_width_m, front_overhang_m,
  /// rear_overhang_m, entry_x_m, lead_out_m, transition_extension_m, line_clearance_m, path_controller,
  /// speed_hold, speed_low_m_s, speed_high_m_s, speed_tolerance_m_s,
  /// speeds_per_round, abort_path_error_m, spin_limit_rad, steer_limit_rad, sample_s, max_steps, integrator.
  static Iso3888Settings fromParams(const ParamReader& r);
  /// The keys (read by fromParams, listed by `vdyn list`).
  static const FieldTable<Iso3888Settings>& fields();
  /// b, m; 0 = the vehicle's own (track + tire width, VehicleFootprint).
  double vehicle_width_m = 0;
  /// Body ends beyond the front and rear axles, m (the seed gives no body: the
  /// scene states them).
  double front_overhang_m = 0.8, rear_overhang_m = 0.7;
  double entry_x_m = 30.0;             ///< straight run before section 1, m
  double lead_out_m = 15.0;            ///< simulated distance after section 5, m
  double transition_extension_m = 4.0; ///< see Iso3888Layout::makeReferencePath
  double line_clearance_m = 0.15;      ///< see Iso3888Layout::makeReferencePath (< 0: lane centres)
  std::string path_controller = "path_control";  ///< the scene's path_control plugin
  std::string speed_hold;              ///< the scene's speed-hold plugin ("" = coast)
  double speed_low_m_s = 8.0;          ///< bracket: must pass
  double speed_high_m_s = 30.0;        ///< bracket: the top (may pass: reported as such)
  double speed_tolerance_m_s = 0.1;    ///< the search stops when the bracket is this narrow
  /// Entry speeds run per round of the search: 1 = bisection; k - 1 = a
  /// k-section (the bracket cut into k equal parts, its k - 1 inner speeds run
  /// at once: fewer sequential rounds for more runs, a gain where there are
  /// threads to run them). The result depends on it, not on the threads.
  int speeds_per_round = 1;
  double abort_path_error_m = 2.0;     ///< a run this far from the path is stopped (fails)
  double spin_limit_rad = 0.5;         ///< |side slip| beyond this: spin-out (fails)
  /// |front road-wheel angle| beyond this, rad: the driver's steering lock (a
  /// passenger car's is about 35-40 deg at the road wheels; 0.7 rad = 40.1 deg).
  /// A run whose path controller steers past it stops and fails there. Without
  /// it, a controller short of grip winds the wheels on toward 80 deg, where
  /// the predicted velocity of (7.13)-(7.16) turns across and the slope error
  /// (7.10) has no value: the run ended as an integrator failure.
  double steer_limit_rad = 0.7;
  double sample_s = 0.005;
  /// Integrator steps a run may take (a run on its way to a solver failure
  /// can crawl with ever smaller steps): beyond, the run stops and fails. A
  /// run through the course takes 2,400-3,700 steps on the 4WS vehicle.
  int max_steps = 40000;
  IntegratorSettings integrator;
  Iso3888Settings() { integrator.accuracy = 1e-6; }
  void validate() const;
};

/// What the test needs of the vehicle's size (from its data, not its scene).
struct VehicleFootprint {
  double width_m = 0;                         ///< overall width (tires' outer edges), m
  double front_axle_x_m = 0, rear_axle_x_m = 0;  ///< axle positions along the chassis x axis, m
  /// The body outline with the settings' overhangs (and width if given).
  BodyOutline body(const Iso3888Settings& settings) const;
};

struct Iso3888Run {
  double speed_m_s = 0;               ///< entry speed
  /// false: the run failed or a guard stopped it (reason); its samples up to
  /// there are kept, `cones` holds the lines it struck before, and the figures
  /// below describe that part only (reports print them for completed runs).
  bool completed = false;
  std::string reason;
  ConeCheck cones;
  bool pass = false;
  double exit_speed_m_s = NAN;        ///< at section 5's end (coasting slows the vehicle); NaN if not reached
  double max_path_error_m = 0;        ///< largest |path distance| of the tracked point
  double peak_lateral_accel_m_s2 = 0; ///< largest |x''| normal to the velocity the controller uses, at the integrator's steps
  double peak_front_steer_deg = 0;
  /// The run's integrator counts; a failed run keeps its steps and wall time.
  RunSummary run;
  std::vector<double> t_s, x_m, y_m, yaw_rad, front_rad, rear_rad, path_error_m;  ///< samples
  void writeCsv(const std::string& path) const;
};

/// Runs the scene (closed loop) through the course at one entry speed. With
/// `animation` (vdyn run --animation), the run's scene is recorded into it
/// (restarted on that scene), with the course's cones as decorations.
Iso3888Run runIso3888(const SceneDescription& scene, const Iso3888Settings& settings, const Iso3888Layout& layout,
                      const BodyOutline& body, double speed_m_s, AnimationRecorder* animation = nullptr);

/// The cones of the course as an animation shows them: along both limits of
/// each coned lane (sections 1, 3, 5), from its start to its end at most
/// `max_spacing_m` apart (equally spaced, both ends included), each base
/// circle tangent to the limit from outside (its centre `cone_base_radius_m`
/// beyond the line), on the ground (z = 0). Section 1's left cones first,
/// then its right ones, then sections 3 and 5 alike.
std::vector<SimTK::Vec3> calcConePositions(const Iso3888Layout& layout, double cone_base_radius_m,
                                           double max_spacing_m = 3.0);

struct Iso3888Result {
  Iso3888Layout layout;
  BodyOutline body;
  std::vector<Iso3888Run> runs;       ///< in the order run
  /// Highest passing entry speed found (the bracket's low end or above), m/s;
  /// the lowest failing one above it; the top of the bracket if it passed.
  double highest_pass_m_s = 0, lowest_fail_m_s = 0;
  bool top_passes = false;
  int best_run = -1, first_fail_run = -1;  ///< indices into runs
};

/// Search on the entry speed: low and high are run (low must pass, else Error
/// naming why); while the bracket [a, b] (a passes, b fails) is wider than the
/// tolerance, a round runs speeds_per_round speeds a + i (b - a) / k (k =
/// speeds_per_round + 1, i = 1..k-1) and takes the new bracket between the
/// lowest failing one and the passing speed below it (bisection for k = 2).
/// Pass/fail need not be monotonic in speed: the result is a passing speed
/// with a failing one within the tolerance above it. The runs of a round (and
/// low and high) are independent: they run on up to `threads` threads
/// (runJobs, vdyn/core/sweep.h), each building its own scene; the result and
/// the order of `runs` do not depend on `threads`.
Iso3888Result findHighestPassingSpeed(const SceneDescription& scene, const Iso3888Settings& settings,
                                      const VehicleFootprint& footprint, int threads = 1);

}  // namespace vdyn
