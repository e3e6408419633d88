#pragma once
// Physical events of a vehicle run, detected after every accepted step:
//   spin_out   |side slip| of the chassis beyond a stated limit
//   rollover   |roll| of the chassis beyond a stated limit
//   lift_off   a tire's normal load at (or below) zero: the wheel left the road
//   left_path  |distance to the reference path| (outputs "*.path_distance_m" of
//              a path controller) beyond a stated limit
// Each is reported once per object with the time it first happened and the
// value; a spin-out or rollover ends the run (RunStopped), because what follows
// is outside the regime the models and the study's claims are for.
#include <functional>
#include <string>
#include <vector>

#include "vdyn/core/error.h"
#include "vdyn/core/fields.h"
#include "vdyn/core/params.h"
#include "vdyn/core/scene.h"

namespace vdyn {

struct EventLimits {
  /// Spin-out when |chassis.side_slip_rad| exceeds this, rad (0.35 rad = 20 deg).
  double spin_out_side_slip_rad = 0.35;
  /// ... checked only while |chassis.forward_speed_m_s| is at least this, m/s.
  double spin_out_min_speed_m_s = 1.0;
  /// Rollover when |chassis.roll_rad| exceeds this, rad (0.8 rad = 46 deg).
  double rollover_roll_rad = 0.8;
  /// Lift-off when a tire's normal load (outputs "<tire>.Fz_N") is at most this, N.
  double lift_off_load_N = 0.0;
  /// Left the path when |"<controller>.path_distance_m"| exceeds this, m
  /// (2 m: the seed's chapter 8 abort limit, half a lane and more).
  double left_path_distance_m = 2.0;
  /// Spin-out, rollover and leaving the path end the run (RunStopped) unless
  /// false; a lift-off only when stop_on_lift_off is true.
  bool stop_on_spin_out = true, stop_on_rollover = true, stop_on_left_path = true, stop_on_lift_off = false;
  /// Checks start at this time, s (lift-off during a settling phase is not an event).
  double start_time_s = 0.0;
  void validate() const;
  /// The limits with no event fatal (a transient analysis' default: a spin is
  /// a result, recorded with its time, not a failure).
  static EventLimits recordOnly();
  /// The data keys (a scene's "analysis": {"events": {...}}): the limits, and
  /// "fatal": the kinds that end the run ([] = none; spin_out, rollover,
  /// left_path, lift_off); absent keys keep the struct's values.
  static const FieldTable<EventLimits>& fields();
};

struct Event {
  std::string kind;    ///< spin_out, rollover, lift_off
  std::string object;  ///< output the event is about, e.g. "chassis.side_slip_rad", "tire_rf.Fz_N"
  double time_s = 0;   ///< end of the step where it was first seen
  double value = 0;    ///< the output's value then
  double limit = 0;    ///< the stated limit
  /// "spin_out at t = 3.52 s: |chassis.side_slip_rad| = 0.3526 beyond the stated limit 0.35"
  std::string describe() const;
};

/// Thrown from the step callback when a stopping event happens.
class RunStopped : public Error {
 public:
  RunStopped(const Event& e, const std::string& where, std::vector<Event> all = {})
      : Error(e.describe() + "; run stopped at " + where), event(e), events(std::move(all)) {}
  Event event;
  std::vector<Event> events;  ///< every event of the run up to this one (this one last)
};

/// [{"kind", "object", "time_s", "value", "limit", "message" (Event::describe)}...]
Json eventsToJson(const std::vector<Event>& events);

class EventMonitor {
 public:
  /// Watches the outputs the scene has (chassis.side_slip_rad, chassis.roll_rad,
  /// every "*.Fz_N", every "*.path_distance_m"); a scene without them has no such events.
  explicit EventMonitor(const Scene& scene, EventLimits limits = {});
  /// Checks `state` (an accepted step); throws RunStopped on a stopping event.
  void check(const SimTK::State& state);
  /// A step callback for simulate(): checks, then calls `next` (if any).
  std::function<void(const SimTK::State&)> callback(std::function<void(const SimTK::State&)> next = {});
  const std::vector<Event>& events() const { return events_; }
  bool has(const std::string& kind) const;
  /// [{"kind", "object", "time_s", "value", "limit", "message"}...]
  Json toJson() const { return eventsToJson(events_); }
  const EventLimits& limits() const { return limits_; }

 private:
  const Scene& scene_;
  EventLimits limits_;
  std::vector<std::string> loads_, paths_;
  bool slip_ = false, roll_ = false, speed_ = false;
  std::vector<Event> events_;
  bool seen(const std::string& kind, const std::string& object) const;
};

}  // namespace vdyn
