#include "vdyn/handling/iso3888.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <fstream>

#include "vdyn/core/animation.h"
#include "vdyn/core/file_io.h"
#include "vdyn/core/interrupt.h"
#include "vdyn/core/recorder.h"
#include "vdyn/core/sweep.h"
#include "vdyn/handling/handling.h"
#include "vdyn/path_control/path_control.h"

namespace vdyn {

using SimTK::Vec2;

double Iso3888Layout::endX() const {
  double x = entry_x_m;
  for (double l : section_length_m) x += l;
  return x;
}

Iso3888Layout Iso3888Layout::make(double b, double x1) {
  requirePositive(b, "ISO 3888-2 vehicle_width_m");
  requireFinite(x1, "ISO 3888-2 entry_x_m");
  Iso3888Layout L;
  L.vehicle_width_m = b;
  L.entry_x_m = x1;
  // ISO 3888-2:2011 Table 1 (docs/iso3888_2_layout.md): lane widths of sections 1, 3, 5.
  const double w1 = 1.1 * b + 0.25, w3 = b + 1.0, w5 = std::max(1.3 * b + 0.25, 3.0);
  const double* len = L.section_length_m;
  const double x2 = x1 + len[0], x3 = x2 + len[1], x4 = x3 + len[2], x5 = x4 + len[3], xEnd = x5 + len[4];
  const double right1 = -0.5 * w1;
  L.lanes.push_back({1, x1, x2, right1, right1 + w1});
  L.lanes.push_back({3, x3, x4, right1 + w1 + 1.0, right1 + w1 + 1.0 + w3});
  L.lanes.push_back({5, x5, xEnd, right1, right1 + w5});
  return L;
}

DoubleLaneChangeParams Iso3888Layout::makeReferencePath(double ext, double clearance) const {
  requireNonNegative(ext, "ISO 3888-2 transition_extension_m");
  const ConeLane &a = lanes.at(0), &b = lanes.at(1), &c = lanes.at(2);
  if (!(2 * ext < std::min({a.x_end_m - a.x_start_m, b.x_end_m - b.x_start_m, c.x_end_m - c.x_start_m})))
    throw Error("ISO 3888-2 transition_extension_m (" + formatValue(ext) +
                " m): the two transitions' extensions must leave part of each lane straight");
  const double hb = 0.5 * vehicle_width_m;
  // Left side `clearance` from the left line (+1) or right side from the right line (-1).
  auto line = [&](const ConeLane& l, int side) {
    if (clearance < 0 || l.width() < 2 * (hb + clearance)) return l.centre();
    return side > 0 ? l.y_left_m - hb - clearance : l.y_right_m + hb + clearance;
  };
  const double y1 = line(a, +1), y3 = line(b, -1), y5 = line(c, +1);
  DoubleLaneChangeParams p;
  p.start_y_m = y1;
  p.first.start_x_m = a.x_end_m - ext;
  p.first.length_m = b.x_start_m - a.x_end_m + 2 * ext;
  p.first.shift_m = y3 - y1;
  p.second.start_x_m = b.x_end_m - ext;
  p.second.length_m = c.x_start_m - b.x_end_m + 2 * ext;
  p.second.shift_m = y5 - y3;
  p.validate();
  return p;
}

std::vector<Vec2> BodyOutline::corners(double x, double y, double psi) const {
  const double c = std::cos(psi), s = std::sin(psi);
  auto at = [&](double bx, double by) { return Vec2(x + c * bx - s * by, y + s * bx + c * by); };
  return {at(front_x_m, half_width_m), at(front_x_m, -half_width_m), at(rear_x_m, -half_width_m),
          at(rear_x_m, half_width_m)};
}

namespace {
/// The X interval where the convex polygon meets the line Y = yc; false if it does not.
bool crossingInterval(const std::vector<Vec2>& poly, double yc, double& lo, double& hi) {
  lo = 1e300, hi = -1e300;
  for (std::size_t i = 0; i < poly.size(); ++i) {
    const Vec2 &a = poly[i], &b = poly[(i + 1) % poly.size()];
    const double da = a[1] - yc, db = b[1] - yc;
    if (da == 0) lo = std::min(lo, a[0]), hi = std::max(hi, a[0]);
    if (da * db < 0) {
      const double x = a[0] + da / (da - db) * (b[0] - a[0]);
      lo = std::min(lo, x), hi = std::max(hi, x);
    }
  }
  return lo <= hi;
}
}  // namespace

ConeCheck checkCones(const Iso3888Layout& L, const BodyOutline& body, const std::vector<double>& t,
                     const std::vector<double>& x, const std::vector<double>& y, const std::vector<double>& yaw) {
  if (x.size() != t.size() || y.size() != t.size() || yaw.size() != t.size())
    throw Error("ISO 3888-2 cone check: sample columns of different lengths");
  ConeCheck out;
  std::vector<bool> struck(2 * L.lanes.size(), false);
  for (std::size_t k = 0; k < t.size(); ++k) {
    const std::vector<Vec2> poly = body.corners(x[k], y[k], yaw[k]);
    for (std::size_t i = 0; i < L.lanes.size(); ++i) {
      const ConeLane& lane = L.lanes[i];
      for (int side = 0; side < 2; ++side) {
        const double yc = side == 0 ? lane.y_left_m : lane.y_right_m;
        double lo, hi;
        if (!struck[2 * i + side] && crossingInterval(poly, yc, lo, hi) && hi >= lane.x_start_m &&
            lo <= lane.x_end_m) {
          struck[2 * i + side] = true;
          out.strikes.push_back({lane.section, side == 0 ? "left" : "right", t[k], x[k]});
        }
      }
      for (const Vec2& c : poly)
        if (c[0] >= lane.x_start_m && c[0] <= lane.x_end_m) {
          const double cl = std::min(c[1] - lane.y_right_m, lane.y_left_m - c[1]);
          if (cl < out.min_clearance_m) out.min_clearance_m = cl, out.min_clearance_section = lane.section;
          // A corner beside the lane beyond a cone line: the body passed
          // outside the cones (or crossed the line between two samples).
          for (int side = 0; side < 2; ++side)
            if (!struck[2 * i + side] && (side == 0 ? c[1] > lane.y_left_m : c[1] < lane.y_right_m)) {
              struck[2 * i + side] = true;
              out.strikes.push_back({lane.section, side == 0 ? "left" : "right", t[k], x[k]});
            }
        }
    }
    double rear = 1e300;
    for (const Vec2& c : poly) rear = std::min(rear, c[0]);
    if (rear > L.endX()) out.reached_exit = true;
  }
  return out;
}

void Iso3888Settings::validate() const {
  requireNonNegative(vehicle_width_m, "ISO 3888-2 vehicle_width_m");
  requireNonNegative(front_overhang_m, "ISO 3888-2 front_overhang_m");
  requireNonNegative(rear_overhang_m, "ISO 3888-2 rear_overhang_m");
  requirePositive(entry_x_m, "ISO 3888-2 entry_x_m");
  requireNonNegative(lead_out_m, "ISO 3888-2 lead_out_m");
  requireNonNegative(transition_extension_m, "ISO 3888-2 transition_extension_m");
  if (path_controller.empty()) throw Error("ISO 3888-2 path_controller: must name the scene's path_control plugin");
  requirePositive(speed_low_m_s, "ISO 3888-2 speed_low_m_s");
  if (!(speed_high_m_s > speed_low_m_s))
    throw Error("ISO 3888-2 speed_high_m_s (" + formatValue(speed_high_m_s) + ") must exceed speed_low_m_s (" +
                formatValue(speed_low_m_s) + ")");
  requirePositive(speed_tolerance_m_s, "ISO 3888-2 speed_tolerance_m_s");
  if (speeds_per_round < 1 || speeds_per_round > 64)
    throw Error("ISO 3888-2 speeds_per_round must be in [1, 64], got " + std::to_string(speeds_per_round));
  requirePositive(abort_path_error_m, "ISO 3888-2 abort_path_error_m");
  requirePositive(spin_limit_rad, "ISO 3888-2 spin_limit_rad");
  requirePositive(steer_limit_rad, "ISO 3888-2 steer_limit_rad");
  requirePositive(sample_s, "ISO 3888-2 sample_s");
  if (max_steps < 1) throw Error("ISO 3888-2 max_steps must be >= 1, got " + std::to_string(max_steps));
}

const FieldTable<Iso3888Settings>& Iso3888Settings::fields() {
  using S = Iso3888Settings;
  static const auto t =
      FieldTable<S>()
          .number("vehicle_width_m", &S::vehicle_width_m, "m", "b; 0 = widest track + tire_width_m")
          .number("front_overhang_m", &S::front_overhang_m, "m", "body front ahead of the front axle")
          .number("rear_overhang_m", &S::rear_overhang_m, "m", "body rear behind the rear axle")
          .number("entry_x_m", &S::entry_x_m, "m", "straight run before section 1")
          .number("lead_out_m", &S::lead_out_m, "m", "run on after section 5")
          .number("transition_extension_m", &S::transition_extension_m, "m",
                  "reference lane changes start/end this far inside the lanes")
          .number("line_clearance_m", &S::line_clearance_m, "m",
                  "reference line: body side this far from the inside cone lines (< 0: lane centres)")
          .string("path_controller", &S::path_controller, "the scene's path_control plugin (its path is replaced)")
          .string("speed_hold", &S::speed_hold, "the scene's speed_hold plugin set to the entry speed; \"\" = coast")
          .number("speed_low_m_s", &S::speed_low_m_s, "m/s", "bisection bracket low end (must pass)")
          .number("speed_high_m_s", &S::speed_high_m_s, "m/s", "bisection bracket high end")
          .number("speed_tolerance_m_s", &S::speed_tolerance_m_s, "m/s", "the search stops at this bracket width")
          .integer("speeds_per_round", &S::speeds_per_round, "",
                   "speeds run at once per round: 1 = bisection, k - 1 = k-section (runs on threads)")
          .number("abort_path_error_m", &S::abort_path_error_m, "m", "a run this far off the path stops and fails")
          .number("spin_limit_rad", &S::spin_limit_rad, "rad", "|side slip| beyond this: spin-out, fails")
          .number("steer_limit_rad", &S::steer_limit_rad, "rad",
                  "|front road-wheel angle| beyond this: past the driver's steering lock, fails")
          .number("sample_s", &S::sample_s, "s", "sampling of the motion (cone check)")
          .integer("max_steps", &S::max_steps, "", "integrator steps a run may take (beyond: stopped, fails)")
          .custom("integrator", "-", "rk_merson 1e-6", "integrator settings",
                  [](const ParamReader& r, S& s) {
                    if (r.has("integrator")) s.integrator = IntegratorSettings::fromParams(r.child("integrator"));
                  })
          .sample(R"({"method": "rk_merson", "accuracy": 1e-6})");
  return t;
}

Iso3888Settings Iso3888Settings::fromParams(const ParamReader& r) {
  Iso3888Settings s;
  fields().read(r, s);
  s.validate();
  return s;
}

BodyOutline VehicleFootprint::body(const Iso3888Settings& s) const {
  BodyOutline b;
  b.front_x_m = front_axle_x_m + s.front_overhang_m;
  b.rear_x_m = rear_axle_x_m - s.rear_overhang_m;
  b.half_width_m = 0.5 * (s.vehicle_width_m > 0 ? s.vehicle_width_m : width_m);
  requirePositive(b.half_width_m, "ISO 3888-2 vehicle width");
  if (!(b.front_x_m > b.rear_x_m)) throw Error("ISO 3888-2: the body's front must be ahead of its rear");
  return b;
}

void Iso3888Run::writeCsv(const std::string& path) const {
  OutputFile f(path);
  f << "t_s,x_m,y_m,yaw_rad,front_rad,rear_rad,path_error_m\n";
  f.precision(10);
  for (std::size_t i = 0; i < t_s.size(); ++i)
    f << t_s[i] << ',' << x_m[i] << ',' << y_m[i] << ',' << yaw_rad[i] << ',' << front_rad[i] << ',' << rear_rad[i]
      << ',' << path_error_m[i] << '\n';
  f.commit();
}

namespace {
/// The built scene's plugin named `name`, or null.
const Plugin* findPlugin(const Scene& scene, const std::string& name) {
  for (const auto& p : scene.getPlugins())
    if (p->name() == name) return p.get();
  return nullptr;
}
double maxAbs(const std::vector<double>& v) {
  double m = 0;
  for (double x : v) m = std::max(m, std::abs(x));
  return m;
}
}  // namespace

std::vector<SimTK::Vec3> calcConePositions(const Iso3888Layout& L, double r, double spacing) {
  requireNonNegative(r, "ISO 3888-2 cone base radius");
  requirePositive(spacing, "ISO 3888-2 cone spacing");
  std::vector<SimTK::Vec3> p_G;
  for (const ConeLane& lane : L.lanes) {
    const double len = lane.x_end_m - lane.x_start_m;
    const int gaps = std::max(1, int(std::ceil(len / spacing - 1e-9)));
    for (const double y : {lane.y_left_m + r, lane.y_right_m - r})
      for (int k = 0; k <= gaps; ++k) p_G.push_back({lane.x_start_m + len * k / gaps, y, 0.0});
  }
  return p_G;
}

Iso3888Run runIso3888(const SceneDescription& desc, const Iso3888Settings& set, const Iso3888Layout& L,
                      const BodyOutline& body, double U, AnimationRecorder* animation) {
  requirePositive(U, "ISO 3888-2 entry speed");
  // The scene's plugins the run reads, from the built scene (typed access):
  // the path controller and the steering it drives, the rear-steer
  // controller's rear steering, the speed hold.
  std::string frontSteer, rearSteer;
  {
    const BuiltScene probe = desc.build();
    const auto* pc = dynamic_cast<const PathControlPlugin*>(findPlugin(probe.scene(), set.path_controller));
    if (!pc)
      throw Error(desc.path() + ": ISO 3888-2 path_controller '" + set.path_controller +
                  "': no path_control plugin of that name");
    frontSteer = pc->steeringPlugin();
    for (const auto& p : probe.scene().getPlugins())
      if (const auto* rs = dynamic_cast<const RearSteerPlugin*>(p.get())) rearSteer = rs->rearSteering();
    if (!set.speed_hold.empty() && !dynamic_cast<const SpeedHoldPlugin*>(findPlugin(probe.scene(), set.speed_hold)))
      throw Error(desc.path() + ": ISO 3888-2 speed_hold '" + set.speed_hold + "': no speed_hold plugin of that name");
  }
  const DoubleLaneChangeParams path = L.makeReferencePath(set.transition_extension_m, set.line_clearance_m);
  const Json pathJson = {{"type", "double_lane_change"},
                         {"start_y_m", path.start_y_m},
                         {"first", {{"start_x_m", path.first.start_x_m}, {"length_m", path.first.length_m}, {"shift_m", path.first.shift_m}}},
                         {"second", {{"start_x_m", path.second.start_x_m}, {"length_m", path.second.length_m}, {"shift_m", path.second.shift_m}}}};
  std::vector<Override> ov = {{"vehicle.initial_speed_m_s", U}, {"plugins." + set.path_controller + ".path", pathJson}};
  if (!set.speed_hold.empty()) {
    ov.push_back({"plugins." + set.speed_hold + ".speed_m_s", U});
  }
  Iso3888Run out;
  out.speed_m_s = U;
  const auto wall0 = std::chrono::steady_clock::now();
  try {
    BuiltScene built = desc.withOverrides(ov).build();
    const Scene& scene = built.scene();
    SimTK::State s = built.makeInitialState();
    const std::string dist = set.path_controller + ".path_distance_m";
    std::vector<std::string> cols = {"chassis.x_m", "chassis.y_m", "chassis.yaw_rad", "chassis.forward_speed_m_s",
                                     dist};
    // The lateral acceleration at the integrator's steps, not at the samples:
    // with the "solved" estimate it is an Acceleration-stage output, which a
    // sample of the interpolated state would pay one evaluation for; a step's
    // end is realized that far already.
    const std::string lateral = set.path_controller + ".lateral_acceleration_m_s2";
    double peakLateral = 0;
    if (!frontSteer.empty()) cols.push_back(frontSteer + ".angle_rad");
    if (!rearSteer.empty()) cols.push_back(rearSteer + ".angle_rad");
    SampleObserver observer;
    if (animation) {
      animation->restart(scene);
      SceneDecorations& d = animation->updDecorations();
      d.cones_G = calcConePositions(L, d.cone_base_radius_m);
      observer = animation->observer();
    }
    Recorder rec(scene, cols, observer);
    SimulationSettings sim;
    // To lead_out_m past section 5 at the entry speed, with time to spare for
    // the speed coasting loses (reached_exit checks the body left the course).
    // The run stops once the chassis is lead_out_m past section 5.
    sim.t_end_s = 1.3 * (L.endX() + set.lead_out_m) / U;
    sim.report_interval_s = set.sample_s;
    sim.integrator = set.integrator;
    // The run ends when the chassis leaves the course (LeftTheCourse) or a
    // guard stops it (Stopped: the reason); either way its samples so far
    // are kept, and the cones it struck before a stop are reported.
    struct LeftTheCourse {};
    struct Stopped {
      std::string why;
    };
    const double xStop = L.endX() + set.lead_out_m;
    std::string stopped;
    // A run that stops or fails keeps its counts up to its last step (simulate's `partial`).
    int steps = 0;
    try {
      out.run = simulate(scene, s, sim, &rec, [&](const SimTK::State& st) {
        peakLateral = std::max(peakLateral, std::abs(scene.evalOutput(lateral, st)));
        if (++steps > set.max_steps)
          throw Stopped{"more than max_steps = " + std::to_string(set.max_steps) + " integrator steps by t = " +
                        formatValue(st.getTime()) + " s"};
        const double d = scene.evalOutput(dist, st);
        if (!(std::abs(d) <= set.abort_path_error_m))
          throw Stopped{"lost the path: " + formatValue(d) + " m from it at t = " + formatValue(st.getTime()) + " s"};
        const double beta = scene.evalOutput("chassis.side_slip_rad", st);
        if (std::abs(beta) > set.spin_limit_rad)
          throw Stopped{"spun out at t = " + formatValue(st.getTime()) + " s (side slip " +
                        formatValue(beta * 180 / SimTK::Pi) + " deg)"};
        if (!frontSteer.empty()) {
          const double delta = scene.evalOutput(frontSteer + ".angle_rad", st);
          if (!(std::abs(delta) <= set.steer_limit_rad))
            throw Stopped{"steered past the lock at t = " + formatValue(st.getTime()) + " s: front road-wheel angle " +
                          formatValue(delta * 180 / SimTK::Pi) + " deg, beyond steer_limit_rad = " +
                          formatValue(set.steer_limit_rad) + " (" +
                          formatValue(set.steer_limit_rad * 180 / SimTK::Pi) + " deg)"};
        }
        if (scene.evalOutput("chassis.x_m", st) > xStop) throw LeftTheCourse{};
      }, &out.run);
    } catch (const LeftTheCourse&) {
    } catch (const Stopped& e) {
      stopped = e.why;
    } catch (const Interrupted&) {
      throw;  // SIGINT/SIGTERM: the search stops, it is not a failed run
    } catch (const Error& e) {  // the integrator or a plugin failed: a failed run, its samples kept
      stopped = e.what();
    }
    out.t_s = rec.time();
    out.x_m = rec.column("chassis.x_m");
    out.y_m = rec.column("chassis.y_m");
    out.yaw_rad = rec.column("chassis.yaw_rad");
    out.path_error_m = rec.column(dist);
    out.front_rad = frontSteer.empty() ? std::vector<double>(out.t_s.size(), 0.0) : rec.column(frontSteer + ".angle_rad");
    out.rear_rad = rearSteer.empty() ? std::vector<double>(out.t_s.size(), 0.0) : rec.column(rearSteer + ".angle_rad");
    out.cones = checkCones(L, body, out.t_s, out.x_m, out.y_m, out.yaw_rad);
    out.max_path_error_m = maxAbs(out.path_error_m);
    out.peak_lateral_accel_m_s2 = peakLateral;
    out.peak_front_steer_deg = maxAbs(out.front_rad) * 180 / SimTK::Pi;
    if (!stopped.empty()) {
      out.completed = false;
      out.reason = stopped;
    } else {
      out.exit_speed_m_s = interpolate(out.x_m, rec.column("chassis.forward_speed_m_s"), L.endX());
      out.completed = out.cones.reached_exit;
      if (!out.completed) out.reason = "did not leave section 5 by the end of the run";
    }
  } catch (const Interrupted&) {
    throw;
  } catch (const Error& e) {  // the scene did not build or start
    out.completed = false;
    out.reason = e.what();
    out.run.wall_time_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - wall0).count();
  }
  out.pass = out.completed && out.cones.strikes.empty();
  return out;
}

Iso3888Result findHighestPassingSpeed(const SceneDescription& desc, const Iso3888Settings& set,
                                      const VehicleFootprint& fp, int threads) {
  set.validate();
  Iso3888Result r;
  r.body = fp.body(set);
  r.layout = Iso3888Layout::make(2 * r.body.half_width_m, set.entry_x_m);
  // One round: the speeds' runs on the threads, appended to r.runs in speed order.
  auto runRound = [&](const std::vector<double>& speeds) {
    std::vector<Iso3888Run> round(speeds.size());
    runJobs(speeds.size(), threads,
            [&](std::size_t i) { round[i] = runIso3888(desc, set, r.layout, r.body, speeds[i]); });
    const int first = int(r.runs.size());
    for (auto& q : round) r.runs.push_back(std::move(q));
    return first;
  };
  int lo = runRound({set.speed_low_m_s, set.speed_high_m_s});
  int hi = lo + 1;
  if (!r.runs[lo].pass) {
    const Iso3888Run& q = r.runs[lo];
    std::string why = q.completed ? std::to_string(q.cones.strikes.size()) + " cone line(s) struck, first in section " +
                                        std::to_string(q.cones.strikes.front().section) + " (" +
                                        q.cones.strikes.front().side + ")"
                                  : q.reason;
    throw Error("ISO 3888-2: the bracket's low end speed_low_m_s = " + formatValue(set.speed_low_m_s) +
                " m/s does not pass (" + why + "); lower it");
  }
  if (r.runs[hi].pass) {
    r.top_passes = true;
    r.best_run = hi;
    r.highest_pass_m_s = set.speed_high_m_s;
    r.lowest_fail_m_s = std::nan("");
    return r;
  }
  double a = set.speed_low_m_s, b = set.speed_high_m_s;
  const int k = set.speeds_per_round + 1;
  while (b - a > set.speed_tolerance_m_s) {
    std::vector<double> speeds;
    for (int i = 1; i < k; ++i) speeds.push_back(k == 2 ? 0.5 * (a + b) : a + i * (b - a) / k);
    const int first = runRound(speeds);
    // The lowest failing speed of the round bounds the bracket from above;
    // the speed below it (a round's speed or a) passes.
    int fail = -1;
    for (int i = 0; i < int(speeds.size()) && fail < 0; ++i)
      if (!r.runs[first + i].pass) fail = i;
    const int passIdx = fail < 0 ? int(speeds.size()) - 1 : fail - 1;
    if (passIdx >= 0) a = speeds[passIdx], lo = first + passIdx;
    if (fail >= 0) b = speeds[fail], hi = first + fail;
  }
  r.best_run = lo;
  r.first_fail_run = hi;
  r.highest_pass_m_s = a;
  r.lowest_fail_m_s = b;
  return r;
}

}  // namespace vdyn
