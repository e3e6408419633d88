#include <algorithm>
#include "vdyn/core/simulation.h"
#include "vdyn/core/cpodes_stepper.h"
#include "vdyn/core/interrupt.h"
#include "vdyn/core/stiffness.h"

#include <chrono>
#include <cmath>
#include <cstdio>
#include <mutex>
#include <set>

namespace vdyn {

void SimulationSettings::validate() const {
  requireFinite(t_end_s, "simulation t_end_s");
  requireNonNegative(report_interval_s, "simulation report_interval_s");
  if (max_steps < 0) throw Error("simulation max_steps must not be negative, got " + std::to_string(max_steps));
  requireNonNegative(min_step_s, "simulation min_step_s");
  if (min_step_count < 1)
    throw Error("simulation min_step_count must be at least 1, got " + std::to_string(min_step_count));
  requireNonNegative(wall_time_budget_s, "simulation wall_time_budget_s");
  if (max_samples < 1) throw Error("simulation max_samples must be at least 1, got " + std::to_string(max_samples));
  requireNonNegative(progress_interval_s, "simulation progress_interval_s");
  integrator.validate();
}

std::string stateSummary(const Scene& scene, const SimTK::State& state) {
  char buf[160];
  std::snprintf(buf, sizeof buf, "t = %.9g s", state.getTime());
  std::string out = buf;
  bool any = false;
  for (const char* name : {"chassis.x_m", "chassis.y_m", "chassis.z_m", "chassis.forward_speed_m_s",
                           "chassis.yaw_rate_rad_s", "chassis.side_slip_rad"}) {
    if (!scene.hasOutput(name)) continue;
    try {
      std::snprintf(buf, sizeof buf, ", %s = %.6g", name, scene.evalOutput(name, state));
      out += buf;
      any = true;
    } catch (const std::exception&) {
    }
  }
  if (!any && state.getSystemStage() >= SimTK::Stage::Model) {
    auto largest = [](const SimTK::Vector& v, int& at) {
      double m = 0;
      at = -1;
      for (int i = 0; i < v.size(); ++i)
        if (!(std::abs(v[i]) <= m)) {
          m = std::abs(v[i]);
          at = i;
        }
      return m;
    };
    int iq = -1, iu = -1;
    const double q = largest(state.getQ(), iq), u = largest(state.getU(), iu);
    std::snprintf(buf, sizeof buf, ", max |q| = %.6g (q[%d]), max |u| = %.6g (u[%d])", q, iq, u, iu);
    out += buf;
  }
  return out;
}

double positionConstraintError(const SimTK::State& state) {
  const SimTK::Vector& qerr = state.getQErr();
  return qerr.size() ? qerr.normInf() : 0.0;
}

namespace {

// The entries of a mode shape (calcModeShape: y = (q, u, z) in Simbody's
// order, largest 1) of at least 0.3, at most four, largest first, named by
// the scene's bodies: "lr.wheel u0 1, lf.wheel u0 0.73" (a q or u no named
// body owns as "q[k]" or "u[k]"); z entries as "z[k]". Empty for an all-zero
// shape.
std::string describeMode(const Scene& scene, const SimTK::State& state, const Eigen::VectorXd& shape) {
  const int nq = state.getNQ(), nu = state.getNU();
  std::vector<int> order;
  for (int i = 0; i < int(shape.size()); ++i)
    if (shape[i] >= 0.3) order.push_back(i);
  std::sort(order.begin(), order.end(), [&](int a, int b) { return shape[a] > shape[b]; });
  if (order.size() > 4) order.resize(4);
  const std::vector<std::string> names = scene.getBodyNames();
  std::string out;
  for (const int i : order) {
    std::string what;
    for (const std::string& name : names) {
      const SimTK::MobilizedBody& b = scene.getBody(name);
      const int first = i < nq ? int(b.getFirstQIndex(state)) : int(b.getFirstUIndex(state));
      const int count = i < nq ? b.getNumQ(state) : b.getNumU(state);
      const int k = (i < nq ? i : i - nq) - first;
      if (i < nq + nu && k >= 0 && k < count) {
        what = name + (i < nq ? " q" : " u") + std::to_string(k);
        break;
      }
    }
    if (what.empty()) what = i < nq ? "q[" + std::to_string(i) + "]" : i < nq + nu ? "u[" + std::to_string(i - nq) + "]"
                                                                                : "z[" + std::to_string(i - nq - nu) + "]";
    char v[24];
    std::snprintf(v, sizeof v, " %.2g", shape[i]);
    out += (out.empty() ? "" : ", ") + what + v;
  }
  return out;
}

// The run's integrator: one of Simbody's (SimTK::Integrator, every method but
// cpodes) or CPodes as vdyn drives it (CpodesStepper), behind the calls the
// loop below makes. Both return after every internal step; reports are
// interpolated, never stepped to.
class Stepping {
 public:
  Stepping(const SimTK::System& system, const IntegratorSettings& settings) {
    if (settings.method == "cpodes") {
      cpodes_.reset(new CpodesStepper(system, settings));
    } else {
      integ_ = makeIntegrator(system, settings);
      integ_->setReturnEveryInternalStep(true);
    }
  }
  /// CPodes, or nullptr for Simbody's integrators.
  CpodesStepper* cpodes() const { return cpodes_.get(); }
  /// `jacobian`: df/dy at `state`, for CPodes's first Newton matrix (others ignore it).
  void initialize(const SimTK::State& state, const Eigen::MatrixXd* jacobian = nullptr) {
    if (cpodes_) cpodes_->initialize(state, jacobian);
    else integ_->initialize(state);
  }
  void setFinalTime(double t) {
    finalTime_ = t;
    if (cpodes_) cpodes_->setFinalTime(t);
    else integ_->setFinalTime(t);
  }
  SimTK::Integrator::SuccessfulStepStatus step() {
    if (!cpodes_) return integ_->stepTo(finalTime_);
    return cpodes_->step() ? SimTK::Integrator::EndOfSimulation : SimTK::Integrator::TimeHasAdvanced;
  }
  /// The last step's end (Simbody's as its integrator leaves it; CPodes's realized through Velocity).
  const SimTK::State& getState() const { return cpodes_ ? cpodes_->getState() : integ_->getState(); }
  /// Simbody's advanced state (the step's end, where getState() may be interpolated); CPodes's step end.
  const SimTK::State& getAdvancedState() const { return cpodes_ ? cpodes_->getState() : integ_->getAdvancedState(); }
  double getTime() const { return cpodes_ ? cpodes_->getTime() : integ_->getTime(); }
  double getPreviousStepSizeTaken() const {
    return cpodes_ ? cpodes_->getPreviousStepSizeTaken() : integ_->getPreviousStepSizeTaken();
  }
  long getNumStepsTaken() const { return cpodes_ ? cpodes_->getNumStepsTaken() : integ_->getNumStepsTaken(); }
  long getNumStepsAttempted() const {
    return cpodes_ ? cpodes_->getNumStepsAttempted() : integ_->getNumStepsAttempted();
  }
  long getNumRealizations() const { return cpodes_ ? cpodes_->getNumRealizations() : integ_->getNumRealizations(); }
  long getNumProjections() const { return cpodes_ ? cpodes_->getNumProjections() : integ_->getNumProjections(); }
  /// Throws Error if Simbody's integrator stopped before the final time.
  void throwIfStoppedEarly(const std::string& method) const {
    if (integ_ && integ_->isSimulationOver() && integ_->getTerminationReason() != SimTK::Integrator::ReachedFinalTime)
      throw Error("simulate: " + method + " stopped early at t = " + formatValue(integ_->getTime()) + " s (" +
                  SimTK::Integrator::getTerminationReasonString(integ_->getTerminationReason()) + ")");
  }

 private:
  std::unique_ptr<SimTK::Integrator> integ_;
  std::unique_ptr<CpodesStepper> cpodes_;
  double finalTime_ = SimTK::Infinity;
};

}  // namespace

RunSummary simulate(const Scene& scene, SimTK::State& state, const SimulationSettings& s,
                    Recorder* recorder, const std::function<void(const SimTK::State&)>& afterStep,
                    RunSummary* partial) {
  if (!scene.isFinalized())
    throw Error("simulate: the scene changed after the state was made; make the state again");
  s.validate();
  const double t0 = state.getTime();
  if (!(s.t_end_s > t0))
    throw Error("simulate: t_end_s (" + formatValue(s.t_end_s) + ") must be after the start time " +
                formatValue(t0));

  RunSummary sum;
  sum.integrator = s.integrator.method;
  // The integrator "auto": RK Merson, and CPodes from the step where RK
  // Merson's steps are found held by its stability limit (stiffness.h).
  const bool autoMethod = s.integrator.method == "auto";
  IntegratorSettings phase = s.integrator;
  if (autoMethod) phase.method = "rk_merson";
  sum.accuracy = s.integrator.accuracy;
  if (const std::string caveat = errorEstimateCaveat(s.integrator); !caveat.empty()) {
    sum.warnings.push_back(caveat);
    // Said once per process on stderr (a sweep may run thousands of cells).
    static std::mutex m;
    static std::set<std::string> said;
    const std::lock_guard<std::mutex> lock(m);
    if (said.insert(caveat).second) std::fprintf(stderr, "vdyn: warning: %s\n", caveat.c_str());
  }
  const auto wall0 = std::chrono::steady_clock::now();

  // Segments: the integrator stops at each restart time (an input whose rate
  // jumps there) and starts afresh from the right, its initialisation
  // projecting the velocities onto the new rate; no error-controlled step
  // passes a velocity-level step.
  std::vector<double> ends;
  for (double r : s.restart_times_s)
    if (r > t0 && r < s.t_end_s) ends.push_back(r);
  std::sort(ends.begin(), ends.end());
  ends.erase(std::unique(ends.begin(), ends.end()), ends.end());
  ends.push_back(s.t_end_s);
  std::size_t seg = 0;
  double segEnd = ends[0];
  long doneSteps = 0, doneAttempts = 0, doneRealizations = 0, doneProjections = 0;  // of finished segments
  long doneJacobians = 0;  // of finished segments, and the stiffness checks'.

  auto integ = std::make_unique<Stepping>(scene.getSystem(), phase);
  integ->setFinalTime(segEnd);
  try {
    integ->initialize(state);
  } catch (const std::exception& e) {
    throw Error(std::string("simulate: initializing ") + s.integrator.method + " failed: " + e.what());
  }
  sum.max_constraint_error = positionConstraintError(integ->getState());
  int ownRealizations = 0;  // the samples' realizations (sampleStep)
  // The counts so far, into `r` (at the end of the run, or of a run that
  // throws: `partial`).
  auto fillCounts = [&](RunSummary& r, double simTime) {
    r.steps = int(doneSteps + integ->getNumStepsTaken());
    r.attempts = int(doneAttempts + integ->getNumStepsAttempted());
    r.realizations = int(doneRealizations + integ->getNumRealizations() + ownRealizations);
    r.projections = int(doneProjections + integ->getNumProjections());
    r.jacobians = int(doneJacobians + (integ->cpodes() ? integ->cpodes()->getNumJacobians() : 0));
    r.sim_time_s = simTime;
    r.wall_time_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - wall0).count();
  };
  const bool reporting = recorder && s.report_interval_s > 0;
  try {

    if (reporting && (s.t_end_s - t0) / s.report_interval_s > double(s.max_samples))
      throw Error("simulate: report_interval_s = " + formatValue(s.report_interval_s) + " s gives " +
                  formatValue(std::ceil((s.t_end_s - t0) / s.report_interval_s)) + " samples over " +
                  formatValue(s.t_end_s - t0) + " s, more than max_samples = " + std::to_string(s.max_samples));
    long k = 1;  // index of the next report time t0 + k * dt (no accumulated drift)
    auto nextReport = [&] { return std::min(s.t_end_s, t0 + k * s.report_interval_s); };
    if (reporting) recorder->record(integ->getState());
    double lastReported = t0;
    // Reporting without State copies or steps to report times: the
    // integrator steps to t_end and the recorder evaluates, in one reused
    // workspace state and unprojected (the samples read positions and
    // velocities, no constraint needs them exact), the interpolant of each
    // step that passed report times: for Simbody's Runge-Kutta family
    // (AbstractIntegratorRep) its own cubic Hermite interpolant (previous Y
    // and YDot kept here, two vectors), for CPodes its own polynomial.
    const bool ownInterpolation = reporting;
    SimTK::Vector yPrev, ydotPrev, yAt;
    double tPrev = t0;
    if (ownInterpolation && !integ->cpodes()) {
      const SimTK::State& s0 = integ->getState();
      scene.getSystem().realize(s0, SimTK::Stage::Acceleration);
      yPrev = s0.getY();
      ydotPrev = s0.getYDot();
    }
    // Samples the report times in (tPrev, end of the step just taken].
    auto sampleStep = [&](const SimTK::State& adv) {
      const double t1 = adv.getTime();
      if (!(t1 > tPrev)) return;
      const CpodesStepper* cp = integ->cpodes();
      // The next step's first stage (the integrator then finds it done and does
      // not count it): counted here, so `realizations` stays the number of
      // forward-dynamics evaluations.
      if (!cp && adv.getSystemStage() < SimTK::Stage::Acceleration) {
        scene.getSystem().realize(adv, SimTK::Stage::Acceleration);
        ++ownRealizations;
      }
      const double tEndTol = 1e-12 * std::max(1.0, std::abs(s.t_end_s));
      while (lastReported < s.t_end_s - tEndTol && nextReport() <= t1 + tEndTol) {
        const double tr = std::min(nextReport(), t1);
        if (cp) {
          cp->interpolate(tr, yAt);
          recorder->recordAt(tr, yAt, adv);
        } else {
          recorder->recordInterpolated(tr, tPrev, yPrev, ydotPrev, adv);
        }
        lastReported = tr;
        ++k;
      }
      if (!cp) {
        yPrev = adv.getY();
        ydotPrev = adv.getYDot();
      }
      tPrev = t1;
    };

    // Simbody 3.7's CPodes can step past the final time and then never report
    // EndOfSimulation (simbody issue #824, fixed after 3.7), so the loop also ends
    // when the integrator's time reaches t_end.
    const double tEndTol = 1e-12 * std::max(1.0, std::abs(s.t_end_s));
    // Run guards (SimulationSettings): each ends the run with an Error that says where.
    int smallSteps = 0;
    auto lastProgress = wall0;
    auto stopped = [&](const std::string& guard) {
      const SimTK::State& at = integ->getState();
      return Error("simulate: " + phase.method + " at accuracy " + formatValue(s.integrator.accuracy) + ": " +
                   guard + "; stopped at " + stateSummary(scene, at) + " after " +
                   std::to_string(integ->getNumStepsTaken()) + " steps (last step " +
                   formatValue(integ->getPreviousStepSizeTaken()) + " s) of the run to t_end " + formatValue(s.t_end_s) +
                   " s");
    };
    // The integrator "auto"'s test, after accepted RK Merson steps 25, 100,
    // 400, ...: the largest of the last ten steps against RK Merson's
    // stability limit at the step's end (one Jacobian, n + 1 evaluations; none
    // while the steps stay below 0.4 of the last check's limit). A run whose
    // steps reach 0.8 of it, set by a damped mode, is held by stability and
    // goes on with CPodes (BDF, Newton), which steps past that mode.
    constexpr int kRecent = 10;
    double recent[kRecent] = {0};
    bool cpodesTried = false;  // or a check failed: no more checks
    long rkSteps = 0, nextCheck = 25;
    // The last check's Jacobian (at the state where CPodes starts if the
    // check says held): CPodes's first Newton matrix is built from it.
    Eigen::MatrixXd checkJacobian;
    double lastStable = 0;  // s, RK Merson's stability limit at the last check
    auto checkStiffness = [&](const SimTK::State& adv, double h) {
      recent[rkSteps % kRecent] = h;
      if (++rkSteps != nextCheck) return false;
      nextCheck *= 4;
      const double hHeld = *std::max_element(recent, recent + kRecent);
      // Far below the last check's limit (the limit would have had to fall by
      // more than half since): no new Jacobian.
      if (hHeld < 0.4 * lastStable) return false;
      long evaluations = 0;
      std::complex<double> lambda;
      double hStable = 0;
      std::string mode;  // the limiting mode's largest entries, named
      try {
        checkJacobian = calcStateDerivativeJacobian(scene.getSystem(), adv, &evaluations);
        hStable = calcRkMersonStabilityLimit(calcEigenvalues(checkJacobian), &lambda);
        if (std::isfinite(hStable)) mode = describeMode(scene, adv, calcModeShape(checkJacobian, lambda));
      } catch (const std::exception& e) {
        // A diagnostic does not end a run: RK Merson goes on, unchecked, and the summary says why.
        char at[40];
        std::snprintf(at, sizeof at, "%.6g", adv.getTime());
        sum.integrator_choice = std::string("rk_merson (the stiffness check at t = ") + at + " s failed: " + e.what() + ")";
        cpodesTried = true;
        return false;
      }
      ownRealizations += int(evaluations);
      ++doneJacobians;
      lastStable = hStable;
      // Held: the steps reach 0.8 of the limit, and the mode that sets it is
      // damped (damping ratio -Re/|lambda| >= 0.7): an oscillatory mode at the
      // limit is one the implicit method would have to resolve as well.
      char buf[320];
      const bool held = hHeld >= 0.8 * hStable && -lambda.real() >= 0.7 * std::abs(lambda);
      std::snprintf(buf, sizeof buf,
                    "the largest of the last %d steps %.3g s at t = %.6g s, RK Merson's stability limit %.3g s "
                    "(eigenvalue %.4g%+.4gi 1/s",
                    kRecent, hHeld, adv.getTime(), hStable, lambda.real(), lambda.imag());
      const std::string limit = std::string(buf) + (mode.empty() ? "" : "; its mode's largest entries: " + mode) + ")";
      char at[40];
      std::snprintf(at, sizeof at, "%.6g", adv.getTime());
      sum.integrator_choice = held ? std::string("rk_merson, then cpodes from t = ") + at + " s (" + limit +
                                         ": held by stability)"
                                   : std::string("rk_merson (") + limit + ")";
      return held;
    };
    // After the switch CPodes must not spend more evaluations than RK Merson's
    // rate before it (evaluations per simulated second, its checks included)
    // would have over the same time, plus an allowance for its start (its
    // first Jacobian and 50 evaluations of order-1 steps); where it does (a
    // closed loop held by accuracy as much as by stability, where CPodes's
    // steps stay short), the run goes back to RK Merson for good. Counts, not
    // times: the choice is the same on any machine.
    double tSwitch = 0, rkRate = 0;
    long cpodesAllowance = 0;
    auto cpodesCostsMore = [&](const SimTK::State& adv) {
      const double allowed = rkRate * (adv.getTime() - tSwitch) + double(cpodesAllowance);
      if (!(double(integ->getNumRealizations()) > allowed)) return false;
      char buf[240];
      std::snprintf(buf, sizeof buf,
                    "; back to rk_merson at t = %.6g s: cpodes took %ld evaluations for %.3g s, where rk_merson's "
                    "rate (%.4g / s) and the allowance give %.0f",
                    adv.getTime(), integ->getNumRealizations(), adv.getTime() - tSwitch, rkRate, allowed);
      sum.integrator_choice += buf;
      return true;
    };
    // Goes on with `method` from the integrator's current state (a step's
    // end): the steps so far count as a finished segment's, and the new
    // integrator starts afresh there.
    // The integrator's counts so far into those of finished segments.
    auto closeCounts = [&] {
      doneSteps += integ->getNumStepsTaken(), doneAttempts += integ->getNumStepsAttempted();
      doneRealizations += integ->getNumRealizations(), doneProjections += integ->getNumProjections();
      if (integ->cpodes()) doneJacobians += integ->cpodes()->getNumJacobians();
    };
    // Starts the integrator at `st` (its initialization projects and realizes
    // the first stage), and the own interpolation there; `what` and `why` go
    // into the message if it fails.
    auto startAt = [&](const SimTK::State& st, const std::string& what, const std::string& why,
                       const Eigen::MatrixXd* jacobian = nullptr) {
      try {
        integ->initialize(st, jacobian);
      } catch (const std::exception& e) {
        throw Error("simulate: " + what + " at t = " + formatValue(st.getTime()) + " s" + why + " failed: " + e.what());
      }
      tPrev = integ->getState().getTime();
      if (ownInterpolation && !integ->cpodes()) {
        const SimTK::State& s1 = integ->getState();
        scene.getSystem().realize(s1, SimTK::Stage::Acceleration);
        yPrev = s1.getY();
        ydotPrev = s1.getYDot();
        tPrev = s1.getTime();
      }
    };
    auto switchTo = [&](const std::string& method) {
      closeCounts();
      const SimTK::State st = integ->getState();
      if (method == "cpodes") {
        cpodesTried = true;
        tSwitch = st.getTime();
        rkRate = double(doneRealizations + ownRealizations) / (tSwitch - t0);
        cpodesAllowance = long(st.getNY()) + 1 + 50;
      }
      phase.method = method;
      integ = std::make_unique<Stepping>(scene.getSystem(), phase);
      integ->setFinalTime(segEnd);
      startAt(st, "integrator auto: starting " + method, "", method == "cpodes" ? &checkJacobian : nullptr);
    };
    for (;;) {
      SimTK::Integrator::SuccessfulStepStatus status;
      try {
        status = integ->step();
      } catch (const std::exception& e) {
        // The last accepted state says where the run broke down (the integrator's
        // message says only that it could not step on).
        std::string what = e.what();
        while (!what.empty() && (what.back() == '\n' || what.back() == ' ')) what.pop_back();
        throw Error("simulate: " + phase.method + " failed at t = " + formatValue(integ->getTime()) +
                    " s; last accepted state: " + stateSummary(scene, integ->getState()) + " (last step " +
                    formatValue(integ->getPreviousStepSizeTaken()) + " s); " + what);
      }
      using S = SimTK::Integrator;
      // A safe point: SIGINT/SIGTERM end the run here (vdyn/core/interrupt.h).
      throwIfInterrupted("at t = " + formatValue(integ->getTime()) + " s of the run to t_end " + formatValue(s.t_end_s) +
                         " s");
      if (ownInterpolation) sampleStep(integ->getAdvancedState());
      if (status == S::TimeHasAdvanced) {
        const SimTK::State& adv = integ->getAdvancedState();
        sum.max_constraint_error = std::max(sum.max_constraint_error, positionConstraintError(adv));
        if (afterStep) afterStep(adv);
        if (s.max_steps > 0 && doneAttempts + integ->getNumStepsAttempted() >= s.max_steps)
          throw stopped("step limit max_steps = " + std::to_string(s.max_steps) + " reached");
        const double h = integ->getPreviousStepSizeTaken();
        smallSteps = (s.min_step_s > 0 && h < s.min_step_s && adv.getTime() < s.t_end_s - tEndTol) ? smallSteps + 1 : 0;
        if (smallSteps >= s.min_step_count)
          throw stopped("step size collapsed: " + std::to_string(smallSteps) + " steps in a row shorter than min_step_s = " +
                        formatValue(s.min_step_s) + " s");
        if (autoMethod && adv.getTime() < segEnd - 1e-9 * std::max(1.0, std::abs(segEnd))) {
          std::string next;
          if (phase.method == "rk_merson" && !cpodesTried && checkStiffness(adv, h)) next = "cpodes";
          if (phase.method == "cpodes" && cpodesCostsMore(adv)) next = "rk_merson";
          if (!next.empty()) {
            switchTo(next);
            continue;
          }
        }
        if (s.wall_time_budget_s > 0 || s.progress) {
          const auto now = std::chrono::steady_clock::now();
          const double wall = std::chrono::duration<double>(now - wall0).count();
          if (s.wall_time_budget_s > 0 && wall > s.wall_time_budget_s)
            throw stopped("wall-clock budget wall_time_budget_s = " + formatValue(s.wall_time_budget_s) + " s used up");
          if (s.progress && std::chrono::duration<double>(now - lastProgress).count() >= s.progress_interval_s) {
            lastProgress = now;
            s.progress(adv, wall);
          }
        }
      }
      const double segTol = 1e-12 * std::max(1.0, std::abs(segEnd));
      if (seg + 1 < ends.size() && (status == S::EndOfSimulation || integ->getTime() >= segEnd - segTol)) {
        // A restart: the next segment starts at the restart time itself (its input from the right).
        closeCounts();
        SimTK::State st = integ->getState();
        st.setTime(segEnd);
        segEnd = ends[++seg];
        integ->setFinalTime(segEnd);
        startAt(st, "restarting " + phase.method, " (an input's rate jumps there)");
        continue;
      }
      if (status == S::EndOfSimulation || integ->getTime() >= s.t_end_s - tEndTol) {
        if (reporting && integ->getTime() > lastReported + tEndTol) recorder->record(integ->getState());
        break;
      }
    }
    integ->throwIfStoppedEarly(phase.method);

  } catch (...) {
    if (partial) {
      *partial = sum;
      fillCounts(*partial, integ->getTime() - t0);
    }
    throw;
  }
  state = integ->getState();
  fillCounts(sum, s.t_end_s - t0);
  if (autoMethod && sum.integrator_choice.empty())
    sum.integrator_choice = "rk_merson (the run ended before its first check at step 25)";
  if (partial) *partial = sum;
  return sum;
}

}  // namespace vdyn
