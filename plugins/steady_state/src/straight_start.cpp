#include "vdyn/steady_state/straight_start.h"

#include "vdyn/core/named_outcome.h"

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

namespace vdyn {

namespace {

/// Yaw rate x horizontal speed of the floating base (m/s^2; 0 without one).
double lateralOf(const Scene& scene, const SteadyStateSolver& solver, const SimTK::State& state) {
  if (!solver.problem().floating_base.isValid()) return 0;
  SimTK::State s = state;
  scene.getSystem().realize(s, SimTK::Stage::Velocity);
  const SimTK::MobilizedBody& b = scene.getMatter().getMobilizedBody(solver.problem().floating_base);
  const SimTK::Vec3 v = b.getBodyOriginVelocity(s);
  return b.getBodyAngularVelocity(s)[2] * std::hypot(v[0], v[1]);
}

/// The tires' normal loads (the outputs ending in ".Fz_N") at straight
/// running, and the search for an unloaded one.
class TireLoads {
 public:
  struct Unloaded {
    std::string tire;  ///< empty: none
    double fz = 0, fz0 = 0;
  };
  TireLoads(const Scene& scene, const SimTK::State& straight) : scene_(scene) {
    for (const auto& n : scene.getOutputNames())
      if (n.size() >= 5 && n.compare(n.size() - 5, 5, ".Fz_N") == 0) {
        const double f0 = scene.evalOutput(n, straight);
        if (f0 > 0) tires_.push_back({&scene.getOutput(n), n, f0});
      }
  }
  bool empty() const { return tires_.empty(); }
  /// The tire least loaded in state `s` (taken by value: it is realized)
  /// relative to straight running, if that is at most `fraction` of its
  /// straight-running load (one realization).
  Unloaded find(SimTK::State s, double fraction) const {
    Unloaded u;
    if (tires_.empty()) return u;
    SimTK::Stage stage = SimTK::Stage::Position;
    for (const Tire& t : tires_) stage = std::max(stage, t.output->stage);
    scene_.getSystem().realize(s, stage);
    for (const Tire& t : tires_) {
      const double f = t.output->eval(s);
      if (f <= fraction * t.fz0 && (u.tire.empty() || f / t.fz0 < u.fz / u.fz0)) u = {t.name, f, t.fz0};
    }
    return u;
  }

 private:
  struct Tire {
    const Output* output;
    std::string name;
    double fz0;
  };
  const Scene& scene_;
  std::vector<Tire> tires_;
};
using Unloaded = TireLoads::Unloaded;

}  // namespace

SteadyStateResult solveFromStraightRunning(SteadyStateSolver& solver, const Scene& scene, const SimTK::State& initial,
                                           const std::function<double(const SimTK::State&)>& frontSteer,
                                           StraightStartReport* report) {
  const double T = solver.problem().time_s;
  if (T == 0) return solver.solve(initial);
  // Straight running: the commands at time 0.
  SteadyStateProblem p0 = solver.problem();
  p0.time_s = 0;
  SteadyStateSolver s0(scene, p0, solver.options());
  SteadyStateResult r0;
  try {
    r0 = s0.solve(initial);
  } catch (const Error& e) {
    throw Error("no steady state at straight running (the commands at time 0), the start of the branch: " +
                std::string(e.what()));
  }
  ArclengthOptions o;
  o.step = T / 20;
  // The arclength counts the scaled state's change too (about 40 T along the
  // ch3 turn's branch at 15 m/s): a largest step of T / 4 took 160-170 steps
  // there, T takes 50-55 (2.4x less CPU per steady state, the same state to
  // 1e-10 and the same fold to its location tolerance).
  o.max_step = T;
  o.min_step = 1e-9 * T;
  o.location_tolerance = 1e-7 * T;
  o.lambda_min = -T;
  o.lambda_max = T;
  o.max_points = 1000;
  o.stop_after_folds = 1;
  o.points_after_last_fold = 1;
  const auto setTime = [](SimTK::State& s, double t) { s.setTime(t); };
  // A wheel lifting off puts a kink into the branch (the tire's normal load
  // reaches zero; past it the wheel hangs and its spin is free: the steady
  // states are no longer isolated). The homotopy stops at the first point
  // past the kink (a tire's normal load zero); a corrector that cannot cross
  // it (the step falls below min_step) is named the same way when the
  // branch, followed again to just before that command time, ends with a
  // tire below 2 % of its straight-running load.
  const auto liftOff = [&](const SteadyStateResult& last, const Unloaded& u, double lambda, const std::string& how) {
    return NamedOutcome("past_lift_off",
                        "no steady state found on the branch from straight running past a wheel lift-off: " + u.tire +
                            " = " + formatValue(u.fz) + " N (" + formatValue(u.fz0) +
                            " N at straight running) at front steer " +
                            (frontSteer ? formatValue(frontSteer(last.state) * 180 / SimTK::Pi)
                                        : std::string("(unknown)")) +
                            " deg (lateral acceleration " + formatValue(lateralOf(scene, solver, last.state)) +
                            " m/s^2), at command time " + formatValue(lambda) + " s of " + formatValue(T) + " s (" +
                            how + ")");
  };
  const TireLoads loads(scene, r0.state);
  if (!loads.empty())
    o.stop_if = [&](const ArclengthPoint& p) {
      return loads.find(solver.getDrivenEulerState(p.x, p.lambda), 0.0).tire.empty()
                 ? std::string()
                 : std::string("a wheel lifted off");
    };
  ArclengthResult ar;
  try {
    ar = continueSteadyState(solver, r0, 0.0, setTime, T, false, o);
  } catch (const Error& e) {
    const std::string msg = e.what(), head = "the step fell below min_step", at = "at lambda = ";
    const auto p = msg.find(at);
    if (msg.find(head) == std::string::npos || p == std::string::npos) throw;
    const double stuck = std::stod(msg.substr(p + at.size()));
    ArclengthOptions ob = o;
    ob.lambda_max = stuck - 1e-3 * T;
    ob.stop_if = nullptr;
    const ArclengthResult before = continueSteadyState(solver, r0, 0.0, setTime, T, false, ob);
    const SteadyStateResult last = solver.makeDrivenResult(before.points.back().x, before.points.back().lambda);
    const Unloaded u = loads.find(last.state, 0.02);
    if (u.tire.empty()) throw;
    throw liftOff(last, u, before.points.back().lambda, "the continuation does not cross the contact's kink: " + msg);
  }
  if (report) {
    report->arclength_steps = ar.steps;
    report->rejected_steps = ar.rejected_steps;
    report->corrector_iterations = ar.corrector_iterations;
    report->jacobians = ar.jacobians;
    report->residual_evaluations = ar.residual_evaluations;
    report->quasi_newton_fallbacks = ar.quasi_newton_fallbacks;
  }
  for (const auto& sp : ar.special) {
    if (sp.kind != "fold" || !(sp.point.lambda < T)) continue;
    const SteadyStateResult f = solver.makeDrivenResult(sp.point.x, sp.point.lambda);
    // A fold at the contact's kink (the branch turns back where a wheel lifts
    // off: its load at the located fold about 3e-8 of the straight-running
    // one in the ch3 design sweep at 15 m/s) is the lift-off.
    const Unloaded u = loads.find(f.state, 1e-5);
    if (!u.tire.empty())
      throw liftOff(f, u, sp.point.lambda, "a fold of the branch where the wheel lifts off, at the contact's kink");
    const double ay = lateralOf(scene, solver, f.state);
    throw NamedOutcome("beyond_fold", "no steady state on the branch from straight running: fold at front steer " +
                (frontSteer ? formatValue(frontSteer(f.state) * 180 / SimTK::Pi) : std::string("(unknown)")) +
                " deg (lateral acceleration " + formatValue(ay) + " m/s^2), at command time " +
                formatValue(sp.point.lambda) + " s of " + formatValue(T) + " s");
  }
  // A fold before the lift-off is the branch's end (found first).
  if (ar.stop_reason == "stopped") {
    const ArclengthPoint& pt = ar.points.back();
    const SteadyStateResult last = solver.makeDrivenResult(pt.x, pt.lambda);
    throw liftOff(last, loads.find(last.state, 0.0), pt.lambda,
                  "the first point of the branch past the contact's kink, the wheel hanging");
  }
  // The two neighbours of time T along the branch: the point at T from their
  // interpolation.
  for (std::size_t i = 1; i < ar.points.size(); ++i) {
    const ArclengthPoint &a = ar.points[i - 1], &b = ar.points[i];
    if (!(a.lambda <= T && b.lambda >= T)) continue;
    const double w = b.lambda > a.lambda ? (T - a.lambda) / (b.lambda - a.lambda) : 0.0;
    SteadyStateResult guess = solver.makeDrivenResult(a.x, a.lambda);
    solver.setGuess(a.x + w * (b.x - a.x), guess);
    return solver.resolve(guess);
  }
  throw Error("steady state from straight running: the homotopy in command time did not reach " + formatValue(T) +
              " s (stopped at " + formatValue(ar.points.back().lambda) + " s: " + ar.stop_reason + ")");
}

}  // namespace vdyn
