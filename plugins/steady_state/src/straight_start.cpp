#include "vdyn/steady_state/straight_start.h"

#include <cmath>

namespace vdyn {

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
  // 1e-12 and the same fold to its location tolerance).
  o.max_step = T;
  o.min_step = 1e-9 * T;
  o.location_tolerance = 1e-7 * T;
  o.lambda_min = -T;
  o.lambda_max = T;
  o.max_points = 1000;
  o.stop_after_folds = 1;
  o.points_after_last_fold = 1;
  const ArclengthResult ar =
      continueSteadyState(solver, r0, 0.0, [](SimTK::State& s, double t) { s.setTime(t); }, T, false, o);
  if (report) {
    report->arclength_steps = ar.steps;
    report->rejected_steps = ar.rejected_steps;
    report->corrector_iterations = ar.corrector_iterations;
  }
  for (const auto& sp : ar.special) {
    if (sp.kind != "fold" || !(sp.point.lambda < T)) continue;
    const SteadyStateResult f = solver.makeDrivenResult(sp.point.x, sp.point.lambda);
    double ay = 0;
    if (solver.problem().floating_base.isValid()) {
      SimTK::State s = f.state;
      scene.getSystem().realize(s, SimTK::Stage::Velocity);
      const SimTK::MobilizedBody& b = scene.getMatter().getMobilizedBody(solver.problem().floating_base);
      const SimTK::Vec3 v = b.getBodyOriginVelocity(s);
      ay = b.getBodyAngularVelocity(s)[2] * std::hypot(v[0], v[1]);
    }
    throw Error("no steady state on the branch from straight running: fold at front steer " +
                (frontSteer ? formatValue(frontSteer(f.state) * 180 / SimTK::Pi) : std::string("(unknown)")) +
                " deg (lateral acceleration " + formatValue(ay) + " m/s^2), at command time " +
                formatValue(sp.point.lambda) + " s of " + formatValue(T) + " s");
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
