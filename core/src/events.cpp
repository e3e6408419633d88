#include "vdyn/core/events.h"

#include <cmath>
#include <cstdio>

#include "vdyn/core/simulation.h"

namespace vdyn {

void EventLimits::validate() const {
  requirePositive(spin_out_side_slip_rad, "event limit spin_out_side_slip_rad");
  requirePositive(rollover_roll_rad, "event limit rollover_roll_rad");
  requireNonNegative(spin_out_min_speed_m_s, "event limit spin_out_min_speed_m_s");
  requireFinite(lift_off_load_N, "event limit lift_off_load_N");
  requireFinite(start_time_s, "event limit start_time_s");
  requirePositive(left_path_distance_m, "event limit left_path_distance_m");
}

EventLimits EventLimits::recordOnly() {
  EventLimits l;
  l.stop_on_spin_out = l.stop_on_rollover = l.stop_on_left_path = l.stop_on_lift_off = false;
  return l;
}

const FieldTable<EventLimits>& EventLimits::fields() {
  using E = EventLimits;
  static const auto t =
      FieldTable<E>()
          .number("spin_out_side_slip_rad", &E::spin_out_side_slip_rad, "rad",
                  "spin_out when |chassis.side_slip_rad| exceeds this")
          .number("spin_out_min_speed_m_s", &E::spin_out_min_speed_m_s, "m/s",
                  "side slip is checked only while |chassis.forward_speed_m_s| is at least this")
          .number("rollover_roll_rad", &E::rollover_roll_rad, "rad", "rollover when |chassis.roll_rad| exceeds this")
          .number("lift_off_load_N", &E::lift_off_load_N, "N",
                  "lift_off when a tire's normal load (<tire>.Fz_N) is at most this")
          .number("left_path_distance_m", &E::left_path_distance_m, "m",
                  "left_path when |<controller>.path_distance_m| exceeds this")
          .number("start_time_s", &E::start_time_s, "s", "no event is checked before this time (a settling phase)")
          .custom("fatal", "-", "[] (transient analysis)",
                  "the event kinds that end the run with an error (spin_out, rollover, left_path, lift_off); the "
                  "others are recorded in summary.json \"events\" with their time and value",
                  [](const ParamReader& r, E& e) {
                    if (!r.has("fatal")) return;
                    const Json& a = r.raw("fatal");
                    if (!a.is_array()) throw Error(r.at("fatal") + ": expected a list of event kinds, got " + a.dump());
                    e.stop_on_spin_out = e.stop_on_rollover = e.stop_on_left_path = e.stop_on_lift_off = false;
                    for (const Json& k : a) {
                      const std::string kind = k.is_string() ? k.get<std::string>() : k.dump();
                      if (kind == "spin_out") e.stop_on_spin_out = true;
                      else if (kind == "rollover") e.stop_on_rollover = true;
                      else if (kind == "left_path") e.stop_on_left_path = true;
                      else if (kind == "lift_off") e.stop_on_lift_off = true;
                      else
                        throw Error(r.at("fatal") + ": unknown event kind '" + kind +
                                    "' (known: spin_out, rollover, left_path, lift_off)");
                    }
                  })
          .sample(R"(["spin_out"])");
  return t;
}

Json eventsToJson(const std::vector<Event>& events) {
  Json a = Json::array();
  for (const auto& e : events)
    a.push_back({{"kind", e.kind},
                 {"object", e.object},
                 {"time_s", e.time_s},
                 {"value", e.value},
                 {"limit", e.limit},
                 {"message", e.describe()}});
  return a;
}

std::string Event::describe() const {
  char buf[256];
  if (kind == "lift_off")
    std::snprintf(buf, sizeof buf, "lift_off at t = %.6g s: %s = %.6g, at or below the stated %.6g", time_s,
                  object.c_str(), value, limit);
  else
    std::snprintf(buf, sizeof buf, "%s at t = %.6g s: |%s| = %.6g beyond the stated limit %.6g", kind.c_str(), time_s,
                  object.c_str(), std::abs(value), limit);
  return buf;
}

EventMonitor::EventMonitor(const Scene& scene, EventLimits limits) : scene_(scene), limits_(limits) {
  limits_.validate();
  slip_ = scene.hasOutput("chassis.side_slip_rad");
  speed_ = scene.hasOutput("chassis.forward_speed_m_s");
  roll_ = scene.hasOutput("chassis.roll_rad");
  for (const auto& n : scene.getOutputNames()) {
    if (n.size() > 5 && n.compare(n.size() - 5, 5, ".Fz_N") == 0) loads_.push_back(n);
    const std::string pd = ".path_distance_m";
    if (n.size() > pd.size() && n.compare(n.size() - pd.size(), pd.size(), pd) == 0) paths_.push_back(n);
  }
}

bool EventMonitor::seen(const std::string& kind, const std::string& object) const {
  for (const auto& e : events_)
    if (e.kind == kind && e.object == object) return true;
  return false;
}

bool EventMonitor::has(const std::string& kind) const {
  for (const auto& e : events_)
    if (e.kind == kind) return true;
  return false;
}

void EventMonitor::check(const SimTK::State& s) {
  const double t = s.getTime();
  if (t < limits_.start_time_s) return;
  auto fire = [&](const std::string& kind, const std::string& object, double value, double limit, bool stop) {
    events_.push_back({kind, object, t, value, limit});
    if (stop) throw RunStopped(events_.back(), stateSummary(scene_, s), events_);
  };
  // Side slip means nothing near standstill (atan2 of two tiny velocities).
  const bool moving = !speed_ || std::abs(scene_.evalOutput("chassis.forward_speed_m_s", s)) >=
                                     limits_.spin_out_min_speed_m_s;
  if (slip_ && moving && !seen("spin_out", "chassis.side_slip_rad")) {
    const double b = scene_.evalOutput("chassis.side_slip_rad", s);
    if (!(std::abs(b) <= limits_.spin_out_side_slip_rad))
      fire("spin_out", "chassis.side_slip_rad", b, limits_.spin_out_side_slip_rad, limits_.stop_on_spin_out);
  }
  if (roll_ && !seen("rollover", "chassis.roll_rad")) {
    const double r = scene_.evalOutput("chassis.roll_rad", s);
    if (!(std::abs(r) <= limits_.rollover_roll_rad))
      fire("rollover", "chassis.roll_rad", r, limits_.rollover_roll_rad, limits_.stop_on_rollover);
  }
  for (const auto& n : loads_) {
    if (seen("lift_off", n)) continue;
    const double fz = scene_.evalOutput(n, s);
    if (fz <= limits_.lift_off_load_N) fire("lift_off", n, fz, limits_.lift_off_load_N, limits_.stop_on_lift_off);
  }
  for (const auto& n : paths_) {
    if (seen("left_path", n)) continue;
    const double d = scene_.evalOutput(n, s);
    if (!(std::abs(d) <= limits_.left_path_distance_m))
      fire("left_path", n, d, limits_.left_path_distance_m, limits_.stop_on_left_path);
  }
}

std::function<void(const SimTK::State&)> EventMonitor::callback(std::function<void(const SimTK::State&)> next) {
  return [this, next](const SimTK::State& s) {
    check(s);
    if (next) next(s);
  };
}


}  // namespace vdyn
