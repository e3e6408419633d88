#include "vdyn/handling/handling.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <limits>

#include "vdyn/core/file_io.h"

namespace vdyn {

using SimTK::Vec3;

namespace {
Vec3 headingLeft(const SimTK::MobilizedBody& ch, const SimTK::State& s) {
  Vec3 x = ch.getBodyRotation(s).x();
  x[2] = 0;
  return Vec3(-x[1], x[0], 0) / std::max(x.norm(), 1e-12);
}
}  // namespace

void ProgrammableCommand::setHold(double a) {
  value_ = {requireInRange(a, -1.2, 1.2, "steering command angle_rad"), 0, 0};
  profile_ = nullptr;
}
void ProgrammableCommand::setValue(const SteerCommandValue& v) {
  requireInRange(v.angle_rad, -1.2, 1.2, "steering command angle_rad");
  requireFinite(v.rate_rad_s, "steering command rate_rad_s");
  requireFinite(v.accel_rad_s2, "steering command accel_rad_s2");
  value_ = v;
  profile_ = nullptr;
}
void ProgrammableCommand::setProfile(Profile p) {
  if (!p) throw Error("steering command: empty profile");
  profile_ = std::move(p);
}
double ProgrammableCommand::getHeldAngle() const {
  return profile_ ? std::numeric_limits<double>::quiet_NaN() : value_.angle_rad;
}

void HandlingVehicle::validate() const {
  const std::string w = "handling vehicle '" + name + "': ";
  if (!scene) throw Error(w + "no scene");
  if (!front) throw Error(w + "no front steering command");
  if (!speed) throw Error(w + "no speed hold");
  if (!make_initial_state) throw Error(w + "no initial-state maker");
  if (rear_strategy && !rear) throw Error(w + "a rear-steer strategy needs a rear steering command");
  requirePositive(wheelbase_m, (w + "wheelbase_m").c_str());
  scene->getBody(chassis_body);
  for (const auto& b : wheel_bodies) scene->getBody(b);
}

double HandlingVehicle::rearAngle(double U, double df) const {
  return rear_strategy ? rear_strategy->calcTarget(U, df, 0, 0).angle_rad : 0.0;
}

void HandlingVehicle::setSteering(double U, const ProgrammableCommand::Profile& fp) const {
  front->setProfile(fp);
  if (!rear) return;
  if (!rear_strategy) {
    rear->setHold(0);
    return;
  }
  auto strat = rear_strategy;
  rear->setProfile([strat, fp, U](double t) {
    const SteerCommandValue f = fp(t);
    const RearSteerTarget r = strat->calcTarget(U, f.angle_rad, f.rate_rad_s, f.accel_rad_s2);
    return SteerCommandValue{r.angle_rad, r.rate_rad_s, r.accel_rad_s2};
  });
}

void HandlingVehicle::holdSteering(double U, double df) const {
  front->setHold(df);
  if (rear) rear->setHold(rearAngle(U, df));
}

void addHandlingOutputs(Scene& sc, const std::string& chassisBody, std::shared_ptr<const ProgrammableCommand> front,
                        std::shared_ptr<const ProgrammableCommand> rear) {
  const SimTK::MobilizedBody ch = sc.getBody(chassisBody);
  sc.addOutput({"handling.lateral_accel_m_s2", "m/s^2", SimTK::Stage::Acceleration, [ch](const SimTK::State& s) {
                  return SimTK::dot(ch.getBodyOriginAcceleration(s), headingLeft(ch, s));
                }});
  sc.addOutput({"handling.front_rad", "rad", SimTK::Stage::Time,
                [front](const SimTK::State& s) { return front->calc(s).angle_rad; }});
  sc.addOutput({"handling.rear_rad", "rad", SimTK::Stage::Time,
                [rear](const SimTK::State& s) { return rear ? rear->calc(s).angle_rad : 0.0; }});
}

SteadyStateProblem makeSteeringUnknownProblem(const HandlingVehicle& v, const std::string& conditionName,
                                              double tolerance, std::function<double(const SimTK::State&)> condition) {
  v.validate();
  SteadyStateProblem p = makeSteadyTurningProblem(*v.scene, v.chassis_body, v.wheel_bodies, 0.0);
  const HandlingVehicle* veh = &v;
  SteadyStateParameter delta;
  delta.name = "front steering angle (rad)";
  delta.typical = 0.01;
  delta.get = [veh](const SimTK::State&) { return veh->front->getHeldAngle(); };
  delta.set = [veh](SimTK::State& s, double df) { veh->holdSteering(veh->speed->getSpeed(s), df); };
  p.parameters.push_back(delta);
  SteadyStateCondition c;
  c.name = conditionName;
  c.tolerance = tolerance;
  c.weight = 1e4;
  c.calc = std::move(condition);
  p.conditions.push_back(c);
  return p;
}


double calcSteadyLateralAcceleration(const SimTK::MobilizedBody& ch, const SimTK::State& s) {
  const Vec3 a = SimTK::cross(Vec3(0, 0, ch.getBodyAngularVelocity(s)[2]), ch.getBodyOriginVelocity(s));
  return SimTK::dot(a, headingLeft(ch, s));
}

double solveSteeringForLateralAcceleration(const HandlingVehicle& v, double U, double ay, SteadyStateResult* out) {
  requirePositive(U, "speed_m_s");
  requireFinite(ay, "lateral_accel_m_s2");
  const SimTK::MobilizedBody ch = v.scene->getBody(v.chassis_body);
  SteadyStateSolver solver(*v.scene, makeSteeringUnknownProblem(v, "lateral acceleration a_y(steady) - a_y (m/s^2)", 1e-10,
                                                                [ch, ay](const SimTK::State& s) {
                                                                  return calcSteadyLateralAcceleration(ch, s) - ay;
                                                                }));
  SimTK::State start = v.make_initial_state(U);
  v.speed->setSpeed(start, U);
  // Start at the Ackermann angle of the turn (l / R, R = U^2 / a_y).
  v.holdSteering(U, std::abs(ay) > 0 ? v.wheelbase_m * ay / (U * U) : 0.0);
  try {
    SteadyStateResult r = solver.solve(start);
    const double df = r.parameters.at(0);
    if (out) *out = std::move(r);
    return df;
  } catch (const Error& e) {
    throw Error("no steady turn of '" + v.name + "' at " + formatValue(U) + " m/s with lateral acceleration " +
                formatValue(ay) + " m/s^2: " + e.what());
  }
}

void HandlingHistory::writeCsv(const std::string& path) const {
  const bool ay = !lateral_accel_m_s2.empty();
  OutputFile f(path);
  f << "t_s,front_rad,rear_rad,yaw_rate_rad_s," << (ay ? "lateral_accel_m_s2," : "")
    << "x_m,y_m,yaw_rad,side_slip_rad,roll_rad\n";
  f.precision(10);
  for (std::size_t i = 0; i < t_s.size(); ++i) {
    f << t_s[i] << ',' << front_rad[i] << ',' << rear_rad[i] << ',' << yaw_rate_rad_s[i] << ',';
    if (ay) f << lateral_accel_m_s2[i] << ',';
    f << x_m[i] << ',' << y_m[i] << ',' << yaw_rad[i] << ',' << side_slip_rad[i] << ',' << roll_rad[i] << '\n';
  }
  f.commit();
}

HandlingHistory runHandlingTransient(const HandlingVehicle& v, double U, double t_end, double sample,
                                     const IntegratorSettings& integrator, double spinLimit, RunSummary* summary,
                                     const std::vector<double>& restarts, double coastFrom,
                                     const SimTK::State* start, bool recordLateralAccel) {
  v.validate();
  SimTK::State s = start ? *start : v.make_initial_state(U);
  if (start) s.setTime(0);
  v.speed->setSpeed(s, U);
  s.invalidateAll(SimTK::Stage::Position);
  v.scene->getSystem().realize(s, SimTK::Stage::Position);
  // The commands at t = 0 may differ from the straight start (profiles start at rest).
  v.scene->getSystem().project(s, 1e-12);
  std::vector<std::string> cols = {"handling.front_rad", "handling.rear_rad", "chassis.yaw_rate_rad_s",
                                   "chassis.x_m",        "chassis.y_m",       "chassis.yaw_rad",
                                   "chassis.side_slip_rad", "chassis.roll_rad"};
  if (recordLateralAccel) cols.push_back("handling.lateral_accel_m_s2");
  Recorder rec(*v.scene, cols);
  SimulationSettings sim;
  sim.report_interval_s = sample;
  sim.integrator = integrator;
  // The restarts are simulate()'s (SimulationSettings::restart_times_s); the
  // run is split only where the speed hold is released.
  sim.restart_times_s = restarts;
  std::vector<double> ends;
  if (coastFrom > 0 && coastFrom < t_end) ends.push_back(coastFrom);
  ends.push_back(t_end);
  if (coastFrom <= 0) v.speed->setEnabled(s, false);
  // A run that spins out (or fails) keeps its counts up to its last step in
  // `summary` (the batteries' cost lines): simulate's `partial` of the segment
  // it ended in, added to the finished segments'.
  RunSummary run, seg;
  auto add = [](RunSummary& to, const RunSummary& r) {
    to.steps += r.steps, to.attempts += r.attempts, to.realizations += r.realizations;
    to.projections += r.projections, to.jacobians += r.jacobians, to.wall_time_s += r.wall_time_s, to.sim_time_s += r.sim_time_s;
    to.max_constraint_error = std::max(to.max_constraint_error, r.max_constraint_error);
  };
  try {
    for (double te : ends) {
      if (s.getTime() >= coastFrom - 1e-12) v.speed->setEnabled(s, false);
      if (!(te > s.getTime())) continue;
      sim.t_end_s = te;
      seg = RunSummary();
      simulate(*v.scene, s, sim, &rec, [&](const SimTK::State& st) {
        const double beta = v.scene->evalOutput("chassis.side_slip_rad", st);
        if (std::abs(beta) > spinLimit)
          throw Error("'" + v.name + "' spun out at t = " + formatSig(st.getTime()) + " s (side slip " +
                      formatSig(beta * 180 / SimTK::Pi, 3) + " deg beyond " + formatSig(spinLimit * 180 / SimTK::Pi, 3) +
                      " deg)");
      }, &seg);
      // The integrator may stop a rounding short of te; the next segment
      // starts at te itself.
      s.setTime(te);
      const RunSummary prev = run;
      run = seg;
      add(run, prev);
    }
  } catch (const Error&) {
    if (summary) {
      RunSummary partial = seg;  // the segment it ended in, up to its last step
      add(partial, run);
      *summary = partial;
    }
    throw;
  }
  if (summary) *summary = run;
  HandlingHistory h;
  h.t_s = rec.time();
  h.front_rad = rec.column("handling.front_rad");
  h.rear_rad = rec.column("handling.rear_rad");
  h.yaw_rate_rad_s = rec.column("chassis.yaw_rate_rad_s");
  if (recordLateralAccel) h.lateral_accel_m_s2 = rec.column("handling.lateral_accel_m_s2");
  h.x_m = rec.column("chassis.x_m");
  h.y_m = rec.column("chassis.y_m");
  h.yaw_rad = rec.column("chassis.yaw_rad");
  h.side_slip_rad = rec.column("chassis.side_slip_rad");
  h.roll_rad = rec.column("chassis.roll_rad");
  return h;
}

std::string formatSig(double v, int digits) {
  char b[64];
  std::snprintf(b, sizeof b, "%.*g", digits, v);
  return b;
}

double interpolate(const std::vector<double>& t, const std::vector<double>& y, double at) {
  if (t.empty()) throw Error("interpolate: no samples");
  if (at <= t.front()) return y.front();
  if (at >= t.back()) return y.back();
  const std::size_t i = std::upper_bound(t.begin(), t.end(), at) - t.begin();
  const double w = (at - t[i - 1]) / (t[i] - t[i - 1]);
  return y[i - 1] + w * (y[i] - y[i - 1]);
}

}  // namespace vdyn
