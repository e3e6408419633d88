#include "vdyn/core/cpodes_stepper.h"

#include <algorithm>
#include <cmath>
#include <utility>

#include "vdyn/core/error.h"
#include "vdyn/core/stiffness.h"

namespace vdyn {

namespace {

// Mirrors of the two SUNDIALS layouts the Jacobian callback reads, as Simbody
// 3.7 bundles them (SimTKmath/Integrators/src/CPodes: sundials_nvector.h's
// struct _generic_N_Vector, nvector_SimTK.h's N_VectorContent_SimTK,
// sundials_direct.h's struct _DlsMat with SUNDIALS_DENSE = 1). Checked at
// every call: the vectors' and the matrix's sizes against N, the matrix type.
struct NVectorMirror {
  void* content;
  void* ops;
};
struct NVectorContentSimTKMirror {
  bool treatAsConst;
  bool ownVector;
  SimTK::Vector* data;
};
struct DlsMatMirror {
  int type, M, N, ldim, mu, ml, s_mu;
  double* data;
  int ldata;
  double** cols;
};
constexpr int kSundialsDense = 1;

const SimTK::Vector& vectorOf(void* nvector) {
  return *static_cast<NVectorContentSimTKMirror*>(static_cast<NVectorMirror*>(nvector)->content)->data;
}

}  // namespace

// The scene's equations for CPodes: f(t, y) and the projection, in the
// stepper's work state.
class CpodesStepper::Ode : public SimTK::CPodesSystem {
 public:
  explicit Ode(CpodesStepper& st) : st_(st) {}

  int explicitODE(SimTK::Real t, const SimTK::Vector& y, SimTK::Vector& ydot) const override {
    try {
      ydot = st_.evaluate(t, y);
    } catch (const std::exception& e) {
      st_.callbackError_ = e.what();
      return SimTK::CPodes::RecoverableError;  // CPodes cuts the step and tries again
    }
    return SimTK::CPodes::Success;
  }

  // Moves (t, y) onto the position and velocity constraints (Simbody's own
  // projection, to the constraint tolerance, local only) and projects the
  // error estimate `err` with it; ycorr = projected - y.
  int project(SimTK::Real t, const SimTK::Vector& y, SimTK::Vector& ycorr, SimTK::Real /*epsProj*/,
              SimTK::Vector& err) const override {
    const SimTK::System& sys = st_.system_;
    SimTK::State& w = st_.work_;
    try {
      st_.setWork(t, y);
      SimTK::ProjectOptions options(st_.settings_.constraint_tolerance);
      options.setOption(SimTK::ProjectOptions::LocalOnly);
      options.setOption(SimTK::ProjectOptions::DontThrow);
      SimTK::ProjectResults results;
      const int nq = w.getNQ(), nu = w.getNU();
      SimTK::VectorView qErr = err(0, nq);
      sys.projectQ(w, qErr, options, results);
      if (results.getExitStatus() != SimTK::ProjectResults::Succeeded) return SimTK::CPodes::RecoverableError;
      bool changed = results.getAnyChangeMade();
      sys.prescribeU(w);
      sys.realize(w, SimTK::Stage::Velocity);
      results.clear();
      SimTK::VectorView uErr = err(nq, nu);
      sys.projectU(w, uErr, options, results);
      if (results.getExitStatus() != SimTK::ProjectResults::Succeeded) return SimTK::CPodes::RecoverableError;
      changed = changed || results.getAnyChangeMade();
      if (changed) ++st_.projections_;
      ycorr = w.getY() - y;
    } catch (const std::exception& e) {
      st_.callbackError_ = e.what();
      return SimTK::CPodes::RecoverableError;
    }
    return SimTK::CPodes::Success;
  }

  void errorHandler(int code, const char* module, const char* function, char* msg) const override {
    st_.cpodesMessage_ = std::string(function ? function : "CPodes") + " (flag " + std::to_string(code) +
                         "): " + (msg ? msg : "");
    (void)module;
  }

 private:
  CpodesStepper& st_;
};

CpodesStepper::CpodesStepper(const SimTK::System& system, const IntegratorSettings& settings)
    : system_(system), settings_(settings), ode_(new Ode(*this)) {}

CpodesStepper::~CpodesStepper() = default;

void CpodesStepper::setWork(double t, const SimTK::Vector& y) {
  work_.setTime(t);
  work_.updY() = y;
  system_.realize(work_, SimTK::Stage::Time);
  system_.prescribeQ(work_);
  system_.realize(work_, SimTK::Stage::Position);
}

const SimTK::Vector& CpodesStepper::evaluate(double t, const SimTK::Vector& y) {
  setWork(t, y);
  system_.prescribeU(work_);
  system_.realize(work_, SimTK::Stage::Acceleration);
  ++evaluations_;
  return work_.getYDot();
}

void CpodesStepper::throwIfFailed(int flag, const std::string& doing) const {
  if (flag >= 0) return;
  std::string why = cpodesMessage_;
  if (!callbackError_.empty()) why += (why.empty() ? "" : "; ") + std::string("last evaluation failed: ") + callbackError_;
  if (why.empty()) why = std::string("flag ") + std::to_string(flag);
  throw Error("cpodes: " + doing + " failed at t = " + formatValue(state_.getTime()) + " s: " + why);
}

void CpodesStepper::initialize(const SimTK::State& state, const Eigen::MatrixXd* jacobian) {
  state_ = state;
  work_ = state;
  system_.realize(state_, SimTK::Stage::Time);
  system_.prescribeQ(state_);
  system_.realize(state_, SimTK::Stage::Position);
  try {
    system_.projectQ(state_, settings_.constraint_tolerance);
    system_.prescribeU(state_);
    system_.realize(state_, SimTK::Stage::Velocity);
    system_.projectU(state_, settings_.constraint_tolerance);
  } catch (const std::exception& e) {
    throw Error("cpodes: projecting the initial state at t = " + formatValue(state.getTime()) +
                " s onto the constraints failed: " + e.what());
  }
  system_.realize(state_, SimTK::Stage::Velocity);
  const int n = state_.getNY();
  handedJacobian_.resize(0, 0);
  if (jacobian) {
    if (jacobian->rows() != n || jacobian->cols() != n)
      throw Error("cpodes: the Jacobian handed to initialize is " + std::to_string(jacobian->rows()) + " x " +
                  std::to_string(jacobian->cols()) + ", the state has " + std::to_string(n) + " entries");
    handedJacobian_ = *jacobian;
  }
  y_ = state_.getY();
  try {
    yp_ = evaluate(state_.getTime(), y_);
  } catch (const std::exception& e) {
    throw Error("cpodes: the state derivative at the start t = " + formatValue(state.getTime()) + " s failed: " +
                e.what());
  }
  cpodes_.reset(new SimTK::CPodes(SimTK::CPodes::ExplicitODE, SimTK::CPodes::BDF, SimTK::CPodes::Newton));
  cpodesMessage_.clear();
  callbackError_.clear();
  double absTol = settings_.accuracy / 10;
  throwIfFailed(cpodes_->init(*ode_, state_.getTime(), y_, yp_, SimTK::CPodes::ScalarScalar, settings_.accuracy, &absTol),
                "init");
  throwIfFailed(cpodes_->setErrHandlerFn(), "setErrHandlerFn");
  throwIfFailed(cpodes_->lapackDense(n), "lapackDense");
  throwIfFailed(cpodes_->dlsSetJacFn(reinterpret_cast<void*>(&CpodesStepper::jacobianCallback), this), "dlsSetJacFn");
  throwIfFailed(cpodes_->setNonlinConvCoef(0.01), "setNonlinConvCoef");
  throwIfFailed(cpodes_->projDefine(), "projDefine");
  if (settings_.max_step_s > 0) throwIfFailed(cpodes_->setMaxStep(settings_.max_step_s), "setMaxStep");
  if (std::isfinite(finalTime_)) throwIfFailed(cpodes_->setStopTime(finalTime_), "setStopTime");
  setMinStep();
}

// A floor under CPodes's step, 1e-12 s times the larger of 1 and |t| at the
// start and the end: where failures (a non-converging corrector, an
// evaluation that throws) would cut the step below it, CPodes stops with an
// error instead of creeping up to the failure in ever smaller steps.
void CpodesStepper::setMinStep() {
  if (!cpodes_) return;
  const double t = std::max({1.0, std::abs(state_.getTime()), std::isfinite(finalTime_) ? std::abs(finalTime_) : 0.0});
  throwIfFailed(cpodes_->setMinStep(1e-12 * t), "setMinStep");
}

void CpodesStepper::setFinalTime(double t) {
  finalTime_ = t;
  if (cpodes_) throwIfFailed(cpodes_->setStopTime(t), "setStopTime");
  setMinStep();
}

bool CpodesStepper::step() {
  if (!cpodes_) throw Error("cpodes: step() before initialize()");
  cpodesMessage_.clear();
  callbackError_.clear();
  double t = state_.getTime();
  const bool stop = std::isfinite(finalTime_);
  const int flag = cpodes_->step(stop ? finalTime_ : t + 1, &t, y_, yp_,
                                 stop ? SimTK::CPodes::OneStepTstop : SimTK::CPodes::OneStep);
  if (flag == SimTK::CPodes::TooClose && stop) {
    // The final time is within rounding of the state's (a restart just
    // before it): nothing to integrate, as Simbody's CPodesIntegrator does.
    state_.setTime(finalTime_);
    system_.realize(state_, SimTK::Stage::Velocity);
    return true;
  }
  throwIfFailed(flag, "a step");
  // An accepted step's last call is normally its projection (no evaluation
  // follows it; on the peer scene every step): the work state then holds the
  // step's end, realized through Velocity, and becomes it. CPodes's y is the
  // unprojected y plus the correction (projected - y): equal to rounding,
  // checked here, as are the time and the stage; else the end is realized.
  bool atEnd = work_.getTime() == t && work_.getSystemStage() >= SimTK::Stage::Velocity;
  if (atEnd) {
    const SimTK::Vector& w = work_.getY();
    for (int i = 0; atEnd && i < y_.size(); ++i)
      atEnd = std::abs(w[i] - y_[i]) <= 4 * SimTK::Eps * std::max(1.0, std::abs(y_[i]));
  }
  if (atEnd) {
    std::swap(state_, work_);
  } else {
    state_.setTime(t);
    state_.updY() = y_;
    system_.realize(state_, SimTK::Stage::Velocity);
  }
  if (!stop) return false;
  return flag == SimTK::CPodes::TstopReturn || t >= finalTime_ - 1e-12 * std::max(1.0, std::abs(finalTime_));
}

void CpodesStepper::interpolate(double t, SimTK::Vector& y) const {
  if (!cpodes_) throw Error("cpodes: interpolate() before initialize()");
  y.resize(state_.getNY());
  const int flag = cpodes_->getDky(t, 0, y);
  if (flag < 0)
    throw Error("cpodes: interpolating at t = " + formatValue(t) + " s failed (flag " + std::to_string(flag) +
                "; the last step ended at " + formatValue(state_.getTime()) + " s)");
}

double CpodesStepper::getPreviousStepSizeTaken() const {
  double h = 0;
  if (cpodes_) cpodes_->getLastStep(&h);
  return h;
}

long CpodesStepper::getNumStepsTaken() const {
  int n = 0;
  if (cpodes_) cpodes_->getNumSteps(&n);
  return n;
}

long CpodesStepper::getNumStepsAttempted() const {
  int n = 0, errFails = 0, convFails = 0;
  if (cpodes_) {
    cpodes_->getNumSteps(&n);
    cpodes_->getNumErrTestFails(&errFails);
    cpodes_->getNumNonlinSolvConvFails(&convFails);
  }
  return long(n) + errFails + convFails;
}

// SUNDIALS's CPDlsDenseJacFn for an explicit ODE: J = df/dy at (t, y), f(t, y) = fy given.
int CpodesStepper::jacobianCallback(int n, double t, void* y, void* fy, void* jac, void* self, void*, void*, void*) {
  auto& st = *static_cast<CpodesStepper*>(self);
  const SimTK::Vector& yv = vectorOf(y);
  const SimTK::Vector& f0 = vectorOf(fy);
  auto* J = static_cast<DlsMatMirror*>(jac);
  if (yv.size() != n || f0.size() != n || J->type != kSundialsDense || J->M != n || J->N != n || J->ldim < n) {
    st.callbackError_ = "CPodes's Jacobian callback arguments are not laid out as vdyn mirrors them (Simbody 3.7's "
                        "bundled SUNDIALS: N_Vector, dense DlsMat); sizes y " + std::to_string(yv.size()) + ", f " +
                        std::to_string(f0.size()) + ", matrix type " + std::to_string(J->type) + " " +
                        std::to_string(J->M) + " x " + std::to_string(J->N) + ", n " + std::to_string(n);
    return SimTK::CPodes::UnrecoverableError;
  }
  if (st.handedJacobian_.size() != 0) {
    // CPodes's first Newton matrix: asked at its first step's predicted y
    // (y0 + h y0'), answered with the Jacobian at y0, as CPodes itself
    // answers with a Jacobian kept from up to 50 steps before. Used once.
    for (int j = 0; j < n; ++j)
      for (int i = 0; i < n; ++i) J->cols[j][i] = st.handedJacobian_(i, j);
    st.handedJacobian_.resize(0, 0);
    return SimTK::CPodes::Success;
  }
  ++st.jacobians_;
  try {
    st.setWork(t, yv);
    st.system_.prescribeU(st.work_);
    calcStateDerivativeJacobianColumns(st.system_, st.work_, f0, J->cols, &st.evaluations_);
  } catch (const std::exception& e) {
    st.callbackError_ = e.what();
    return SimTK::CPodes::RecoverableError;
  }
  return SimTK::CPodes::Success;
}

}  // namespace vdyn
