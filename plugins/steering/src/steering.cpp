#include "vdyn/core/text.h"
#include "vdyn/steering/steering.h"
#include "vdyn/steering/commands.h"

#include <sstream>

#include "vdyn/core/fields.h"

#include <cmath>
#include <functional>

namespace vdyn {

using SimTK::Vec3;

SteerCommandValue SteeringCommand::calcAt(double t) const {
  const SteerCommandValue v = DoCalc(t);
  assert(std::isfinite(v.angle_rad) && std::isfinite(v.rate_rad_s) && std::isfinite(v.accel_rad_s2));
  return v;
}

HoldCommand::HoldCommand(double a) { setAngle(a); }

void HoldCommand::setAngle(double a) { angle_ = requireInRange(a, -1.2, 1.2, "steering hold angle_rad"); }

SmoothStepCommand::SmoothStepCommand(double d0, double D, double t0, double T)
    : d0_(requireInRange(d0, -1.2, 1.2, "steering initial_rad")),
      D_(requireFinite(D, "steering step")),
      t0_(requireFinite(t0, "steering start_time_s")),
      T_(requirePositive(T, "steering duration_s")) {
  requireInRange(d0 + D, -1.2, 1.2, "steering final_rad");
}

SteerCommandValue SmoothStepCommand::DoCalc(double t) const {
  if (t <= t0_) return {d0_, 0, 0};
  if (t >= t0_ + T_) return {d0_ + D_, 0, 0};
  const double s = (t - t0_) / T_;
  // (7.4) and its derivatives: d/ds = 12 s (1 - s)^2, d2/ds2 = 12 - 48 s + 36 s^2.
  return {d0_ + D_ * s * s * (6 - 8 * s + 3 * s * s), D_ / T_ * 12 * s * (1 - s) * (1 - s),
          D_ / (T_ * T_) * (12 - 48 * s + 36 * s * s)};
}

StepSequenceCommand::StepSequenceCommand(double d0, std::vector<Step> steps)
    : d0_(requireInRange(d0, -1.2, 1.2, "steering initial_rad")) {
  if (steps.empty()) throw Error("steering steps: the sequence is empty");
  double total = d0;
  for (const Step& k : steps) {
    steps_.emplace_back(0.0, k.change_rad, k.start_time_s, k.duration_s);
    total += k.change_rad;
  }
  requireInRange(total, -1.2, 1.2, "steering final angle of the steps");
}

SteerCommandValue StepSequenceCommand::DoCalc(double t) const {
  SteerCommandValue v{d0_, 0, 0};
  for (const auto& k : steps_) {
    const SteerCommandValue c = k.calcAt(t);
    v.angle_rad += c.angle_rad;
    v.rate_rad_s += c.rate_rad_s;
    v.accel_rad_s2 += c.accel_rad_s2;
  }
  return v;
}

namespace {
// The keys of each built-in steering command (read by its factory, listed by `vdyn list`).
struct HoldKeys {
  double angle_rad = 0;
};
const FieldTable<HoldKeys>& holdFields() {
  static const auto t = FieldTable<HoldKeys>().number("angle_rad", &HoldKeys::angle_rad, "rad", "held angle, + left");
  return t;
}
struct SmoothStepKeys {
  double initial_rad = 0, final_rad = 0, start_time_s = 0, duration_s = 0;
};
const FieldTable<SmoothStepKeys>& smoothStepFields() {
  using K = SmoothStepKeys;
  static const auto t = FieldTable<K>()
                            .number("initial_rad", &K::initial_rad, "rad", "angle before the step, + left")
                            .number("final_rad", &K::final_rad, "rad", "angle after the step, + left", true)
                            .number("start_time_s", &K::start_time_s, "s", "t_i, start of the step", true)
                            .number("duration_s", &K::duration_s, "s", "T, duration of the step", true);
  return t;
}
struct StepKeys {
  double start_time_s = 0, duration_s = 0, change_rad = 0;
};
const FieldTable<StepKeys>& stepFields() {
  static const auto t = FieldTable<StepKeys>()
                            .number("start_time_s", &StepKeys::start_time_s, "s", "start of the step", true)
                            .number("duration_s", &StepKeys::duration_s, "s", "duration of the step", true)
                            .number("change_rad", &StepKeys::change_rad, "rad", "change of angle, + left", true);
  return t;
}
struct StepsKeys {
  double initial_rad = 0;
  std::vector<StepSequenceCommand::Step> steps;
};
const FieldTable<StepsKeys>& stepsFields() {
  static const auto t =
      FieldTable<StepsKeys>()
          .number("initial_rad", &StepsKeys::initial_rad, "rad", "angle before the first step, + left")
          .custom("steps", "-", "required", "[{start_time_s (s), duration_s (s), change_rad (rad)}, ...], each required",
                  [](const ParamReader& r, StepsKeys& k) {
                    for (const auto& e : r.array("steps")) {
                      const StepKeys s = stepFields().read(e);
                      k.steps.push_back({s.start_time_s, s.duration_s, s.change_rad});
                    }
                  })
          .sample("[{\"start_time_s\": 0, \"duration_s\": 1, \"change_rad\": 0.01}]");
  return t;
}
}  // namespace

void registerSteeringCommands(PluginRegistry& registry) {
  registry.addChoice<SteeringCommand>(
      "steering_command", "hold",
      [](const ParamReader& r, const NoContext&) {
        return std::make_unique<HoldCommand>(holdFields().read(r).angle_rad);
      },
      typeInfo("a constant angle (HoldCommand; adjustable angle_rad)", holdFields()));
  registry.addChoice<SteeringCommand>(
      "steering_command", "smooth_step",
      [](const ParamReader& r, const NoContext&) {
        const SmoothStepKeys k = smoothStepFields().read(r);
        return std::make_unique<SmoothStepCommand>(k.initial_rad, k.final_rad - k.initial_rad, k.start_time_s,
                                                   k.duration_s);
      },
      typeInfo("the seed's smooth step (7.4)-(7.5) from initial_rad to final_rad", smoothStepFields()));
  registry.addChoice<SteeringCommand>(
      "steering_command", "steps",
      [](const ParamReader& r, const NoContext&) {
        StepsKeys k = stepsFields().read(r);
        return std::make_unique<StepSequenceCommand>(k.initial_rad, std::move(k.steps));
      },
      typeInfo("smooth steps (7.4) added together (Figure 7.2's open-loop inputs)", stepsFields()));
  registerWaveformCommands(registry);
}

namespace {
const PluginRegistry& builtinCommands() {
  static const PluginRegistry r = [] {
    PluginRegistry reg;
    registerSteeringCommands(reg);
    return reg;
  }();
  return r;
}
}  // namespace

std::shared_ptr<const SteeringCommand> makeSteeringCommand(const ParamReader& r, const PluginRegistry* registry) {
  const PluginRegistry& reg = registry ? *registry : builtinCommands();
  std::shared_ptr<const SteeringCommand> cmd =
      reg.createChoice<SteeringCommand>("steering_command", r.string("type"), r, NoContext{}, r.at("type"));
  // A road-wheel angle beyond 45 deg is no steering angle (a degree typed as radians).
  for (const char* k : {"angle_rad", "initial_rad", "final_rad"})
    if (r.has(k) && std::abs(r.number(k)) > SimTK::Pi / 4)
      throw Error(r.at(k) + " must lie in [-0.785398, 0.785398] rad (+-45 deg), got " + formatValue(r.number(k)));
  r.requireAllKeysRead();
  return cmd;
}

// ---------------------------------------------------------------------------
SteeringConstraintImpl::SteeringConstraintImpl(SimTK::SimbodyMatterSubsystem& matter,
                                               const SimTK::MobilizedBody& chassis,
                                               const SimTK::MobilizedBody& knuckle,
                                               const SimTK::UnitVec3& spinAxis_K,
                                               std::shared_ptr<const SteeringCommand> command)
    : Implementation(matter, 1, 0, 0), spin_K_(spinAxis_K), command_(std::move(command)) {
  if (!command_) throw Error("steering constraint: no command");
  B_ = addConstrainedBody(chassis);
  F_ = addConstrainedBody(knuckle);
}

// Notation (all in the constraint's ancestor frame A): b = chassis x axis,
// f = knuckle spin axis, w_B, w_F their angular velocities.
void SteeringConstraintImpl::calcPositionErrors(
    const SimTK::State& s, const SimTK::Array_<SimTK::Transform, SimTK::ConstrainedBodyIndex>& X_AB,
    const SimTK::Array_<SimTK::Real, SimTK::ConstrainedQIndex>&, SimTK::Array_<SimTK::Real>& perr) const {
  const Vec3 b = getBodyRotation(X_AB, B_).x();
  const Vec3 f = getBodyRotation(X_AB, F_) * Vec3(spin_K_);
  perr[0] = SimTK::dot(b, f) + std::sin(command_->calc(s).angle_rad);
}

void SteeringConstraintImpl::calcPositionDotErrors(
    const SimTK::State& s, const SimTK::Array_<SimTK::SpatialVec, SimTK::ConstrainedBodyIndex>& V_AB,
    const SimTK::Array_<SimTK::Real, SimTK::ConstrainedQIndex>&, SimTK::Array_<SimTK::Real>& pverr) const {
  const Vec3 b = getBodyRotationFromState(s, B_).x();
  const Vec3 f = getBodyRotationFromState(s, F_) * Vec3(spin_K_);
  const Vec3 w_B = getBodyAngularVelocity(V_AB, B_), w_F = getBodyAngularVelocity(V_AB, F_);
  const SteerCommandValue c = command_->calc(s);
  // d/dt (b . f) = (w_F - w_B) . (f x b)
  pverr[0] = SimTK::dot(w_F - w_B, SimTK::cross(f, b)) + std::cos(c.angle_rad) * c.rate_rad_s;
}

void SteeringConstraintImpl::calcPositionDotDotErrors(
    const SimTK::State& s, const SimTK::Array_<SimTK::SpatialVec, SimTK::ConstrainedBodyIndex>& A_AB,
    const SimTK::Array_<SimTK::Real, SimTK::ConstrainedQIndex>&, SimTK::Array_<SimTK::Real>& paerr) const {
  const Vec3 b = getBodyRotationFromState(s, B_).x();
  const Vec3 f = getBodyRotationFromState(s, F_) * Vec3(spin_K_);
  const Vec3 w_B = getBodyAngularVelocityFromState(s, B_), w_F = getBodyAngularVelocityFromState(s, F_);
  const Vec3 a_B = getBodyAngularAcceleration(A_AB, B_), a_F = getBodyAngularAcceleration(A_AB, F_);
  const Vec3 bdot = SimTK::cross(w_B, b), fdot = SimTK::cross(w_F, f);
  const SteerCommandValue c = command_->calc(s);
  // (A.3)-(A.4): the second derivative of Phi, with the commanded acceleration.
  paerr[0] = SimTK::dot(a_F - a_B, SimTK::cross(f, b)) +
             SimTK::dot(w_F - w_B, SimTK::cross(fdot, b) + SimTK::cross(f, bdot)) +
             std::cos(c.angle_rad) * c.accel_rad_s2 - std::sin(c.angle_rad) * c.rate_rad_s * c.rate_rad_s;
}

void SteeringConstraintImpl::addInPositionConstraintForces(
    const SimTK::State& s, const SimTK::Array_<SimTK::Real>& multipliers,
    SimTK::Array_<SimTK::SpatialVec, SimTK::ConstrainedBodyIndex>& bodyForcesInA,
    SimTK::Array_<SimTK::Real, SimTK::ConstrainedQIndex>&) const {
  const Vec3 b = getBodyRotationFromState(s, B_).x();
  const Vec3 f = getBodyRotationFromState(s, F_) * Vec3(spin_K_);
  // Torques whose power equals lambda times the velocity-level error.
  const Vec3 torque_F = multipliers[0] * SimTK::cross(f, b);
  addInBodyTorque(s, F_, torque_F, bodyForcesInA);
  addInBodyTorque(s, B_, -torque_F, bodyForcesInA);
}

// ---------------------------------------------------------------------------
// State-driven steering.
void SteeringStateSpec::validate(const std::string& where) const {
  requireInRange(initial_angle_rad, -1.2, 1.2, where + " initial_angle_rad");
  requirePositive(steer_body_inertia_kg_m2, where + " steer_body_inertia_kg_m2");
}

SteeringStateConstraintImpl::SteeringStateConstraintImpl(SimTK::SimbodyMatterSubsystem& matter,
                                                         const SimTK::MobilizedBody& chassis,
                                                         const SimTK::MobilizedBody& knuckle,
                                                         const SimTK::UnitVec3& spinAxis_K,
                                                         const SimTK::MobilizedBody& steerBody)
    : Implementation(matter, 1, 0, 0), spin_K_(spinAxis_K) {
  B_ = addConstrainedBody(chassis);
  F_ = addConstrainedBody(knuckle);
  D_ = addConstrainedBody(steerBody);
}

// Notation as SteeringConstraintImpl, plus d = the steer body's eta axis and
// w_D its angular velocity. Phi = b . f - b . d (A.1), with b . d = -sin(delta).
void SteeringStateConstraintImpl::calcPositionErrors(
    const SimTK::State&, const SimTK::Array_<SimTK::Transform, SimTK::ConstrainedBodyIndex>& X_AB,
    const SimTK::Array_<SimTK::Real, SimTK::ConstrainedQIndex>&, SimTK::Array_<SimTK::Real>& perr) const {
  const Vec3 b = getBodyRotation(X_AB, B_).x();
  const Vec3 f = getBodyRotation(X_AB, F_) * Vec3(spin_K_);
  const Vec3 d = getBodyRotation(X_AB, D_).y();
  perr[0] = SimTK::dot(b, f - d);
}

void SteeringStateConstraintImpl::calcPositionDotErrors(
    const SimTK::State& s, const SimTK::Array_<SimTK::SpatialVec, SimTK::ConstrainedBodyIndex>& V_AB,
    const SimTK::Array_<SimTK::Real, SimTK::ConstrainedQIndex>&, SimTK::Array_<SimTK::Real>& pverr) const {
  const Vec3 b = getBodyRotationFromState(s, B_).x();
  const Vec3 f = getBodyRotationFromState(s, F_) * Vec3(spin_K_);
  const Vec3 d = getBodyRotationFromState(s, D_).y();
  const Vec3 w_B = getBodyAngularVelocity(V_AB, B_), w_F = getBodyAngularVelocity(V_AB, F_),
             w_D = getBodyAngularVelocity(V_AB, D_);
  // (A.2): d/dt (b . g) = (w_G - w_B) . (g x b) for g = f, d.
  pverr[0] = SimTK::dot(w_F - w_B, SimTK::cross(f, b)) - SimTK::dot(w_D - w_B, SimTK::cross(d, b));
}

void SteeringStateConstraintImpl::calcPositionDotDotErrors(
    const SimTK::State& s, const SimTK::Array_<SimTK::SpatialVec, SimTK::ConstrainedBodyIndex>& A_AB,
    const SimTK::Array_<SimTK::Real, SimTK::ConstrainedQIndex>&, SimTK::Array_<SimTK::Real>& paerr) const {
  const Vec3 b = getBodyRotationFromState(s, B_).x();
  const Vec3 w_B = getBodyAngularVelocityFromState(s, B_);
  const Vec3 a_B = getBodyAngularAcceleration(A_AB, B_);
  const Vec3 bdot = SimTK::cross(w_B, b);
  // (A.3)-(A.4) for one term b . g of a body G with angular velocity w_G.
  auto term = [&](const Vec3& g, const Vec3& w_G, const Vec3& a_G) {
    const Vec3 gdot = SimTK::cross(w_G, g);
    return SimTK::dot(a_G - a_B, SimTK::cross(g, b)) + SimTK::dot(w_G - w_B, SimTK::cross(gdot, b) + SimTK::cross(g, bdot));
  };
  const Vec3 f = getBodyRotationFromState(s, F_) * Vec3(spin_K_);
  const Vec3 d = getBodyRotationFromState(s, D_).y();
  paerr[0] = term(f, getBodyAngularVelocityFromState(s, F_), getBodyAngularAcceleration(A_AB, F_)) -
             term(d, getBodyAngularVelocityFromState(s, D_), getBodyAngularAcceleration(A_AB, D_));
}

void SteeringStateConstraintImpl::addInPositionConstraintForces(
    const SimTK::State& s, const SimTK::Array_<SimTK::Real>& multipliers,
    SimTK::Array_<SimTK::SpatialVec, SimTK::ConstrainedBodyIndex>& bodyForcesInA,
    SimTK::Array_<SimTK::Real, SimTK::ConstrainedQIndex>&) const {
  const Vec3 b = getBodyRotationFromState(s, B_).x();
  const Vec3 f = getBodyRotationFromState(s, F_) * Vec3(spin_K_);
  const Vec3 d = getBodyRotationFromState(s, D_).y();
  // Torques whose power equals lambda times the velocity-level error.
  const Vec3 torque_F = multipliers[0] * SimTK::cross(f, b), torque_D = -multipliers[0] * SimTK::cross(d, b);
  addInBodyTorque(s, F_, torque_F, bodyForcesInA);
  addInBodyTorque(s, D_, torque_D, bodyForcesInA);
  addInBodyTorque(s, B_, -torque_F - torque_D, bodyForcesInA);
}

namespace {
/// Prescribes the steer body's acceleration u' = delta'' from a law (Simbody
/// calls it while realizing Dynamics, so the law may use velocities).
class SteeringLawMotion : public SimTK::Motion::Custom::Implementation {
 public:
  explicit SteeringLawMotion(std::function<double(const SimTK::State&)> law) : law_(std::move(law)) {}
  Implementation* clone() const override { return new SteeringLawMotion(*this); }
  SimTK::Motion::Level getLevel(const SimTK::State&) const override { return SimTK::Motion::Acceleration; }
  void calcPrescribedAcceleration(const SimTK::State& s, int nu, SimTK::Real* udot) const override {
    assert(nu == 1);
    (void)nu;
    udot[0] = law_(s);
  }

 private:
  std::function<double(const SimTK::State&)> law_;
};
}  // namespace

double headingAngle(const SimTK::State& s, const SimTK::MobilizedBody& chassis, const SimTK::MobilizedBody& knuckle,
                    const SimTK::UnitVec3& spinAxis_K) {
  const SimTK::Rotation& R = chassis.getBodyRotation(s);
  const Vec3 f = knuckle.getBodyRotation(s) * Vec3(spinAxis_K);
  return std::atan2(-SimTK::dot(R.x(), f), SimTK::dot(R.y(), f));
}

namespace {
/// The rack follows a time command: Phi = x - k q(t) = 0 on the rack slider's
/// coordinate x, with its time derivatives x' - k q', x'' - k q''.
class RackCommandConstraintImpl : public SimTK::Constraint::Custom::Implementation {
 public:
  RackCommandConstraintImpl(SimTK::SimbodyMatterSubsystem& matter, const SimTK::MobilizedBody& rack, double k,
                            double limit, std::shared_ptr<const SteeringCommand> command, std::string who)
      : Implementation(matter, 1, 0, 0), k_(k), limit_(limit), command_(std::move(command)), who_(std::move(who)) {
    M_ = addConstrainedMobilizer(rack);
  }
  Implementation* clone() const override { return new RackCommandConstraintImpl(*this); }
  void calcPositionErrors(const SimTK::State& s, const SimTK::Array_<SimTK::Transform, SimTK::ConstrainedBodyIndex>&,
                          const SimTK::Array_<SimTK::Real, SimTK::ConstrainedQIndex>& q,
                          SimTK::Array_<SimTK::Real>& perr) const override {
    const double x = k_ * command_->calc(s).angle_rad;
    if (!(std::abs(x) <= limit_))
      throw Error("steering plugin '" + who_ + "': the command asks a rack travel of " + formatValue(x) +
                  " m at t = " + formatValue(s.getTime()) + " s, beyond rack_travel_limit_m " + formatValue(limit_));
    perr[0] = getOneQ(s, q, M_, SimTK::MobilizerQIndex(0)) - x;
  }
  void calcPositionDotErrors(const SimTK::State& s, const SimTK::Array_<SimTK::SpatialVec, SimTK::ConstrainedBodyIndex>&,
                             const SimTK::Array_<SimTK::Real, SimTK::ConstrainedQIndex>& qdot,
                             SimTK::Array_<SimTK::Real>& pverr) const override {
    pverr[0] = getOneQDot(s, qdot, M_, SimTK::MobilizerQIndex(0)) - k_ * command_->calc(s).rate_rad_s;
  }
  void calcPositionDotDotErrors(const SimTK::State& s,
                                const SimTK::Array_<SimTK::SpatialVec, SimTK::ConstrainedBodyIndex>&,
                                const SimTK::Array_<SimTK::Real, SimTK::ConstrainedQIndex>& qdotdot,
                                SimTK::Array_<SimTK::Real>& paerr) const override {
    paerr[0] = getOneQDotDot(s, qdotdot, M_, SimTK::MobilizerQIndex(0)) - k_ * command_->calc(s).accel_rad_s2;
  }
  void addInPositionConstraintForces(const SimTK::State& s, const SimTK::Array_<SimTK::Real>& multipliers,
                                     SimTK::Array_<SimTK::SpatialVec, SimTK::ConstrainedBodyIndex>&,
                                     SimTK::Array_<SimTK::Real, SimTK::ConstrainedQIndex>& qForces) const override {
    addInOneQForce(s, M_, SimTK::MobilizerQIndex(0), multipliers[0], qForces);
  }

 private:
  SimTK::ConstrainedMobilizerIndex M_;
  double k_, limit_;
  std::shared_ptr<const SteeringCommand> command_;
  std::string who_;
};
}  // namespace

double steeringAngle(const SimTK::State& s, const SimTK::MobilizedBody& chassis, const SimTK::MobilizedBody& knuckle,
                     const SimTK::UnitVec3& spinAxis_K) {
  const Vec3 b = chassis.getBodyRotation(s).x();
  const Vec3 f = knuckle.getBodyRotation(s) * Vec3(spinAxis_K);
  return std::asin(std::max(-1.0, std::min(1.0, -SimTK::dot(b, f))));
}

// ---------------------------------------------------------------------------
SteeringPlugin::SteeringPlugin(std::string name, std::string chassisBody, std::vector<std::string> knuckles,
                               std::shared_ptr<const SteeringCommand> command, SimTK::UnitVec3 spinAxis_K)
    : ConstraintPlugin("steering", std::move(name)),
      chassis_(std::move(chassisBody)),
      knuckles_(std::move(knuckles)),
      command_(std::move(command)),
      spin_K_(spinAxis_K) {
  if (!command_) throw Error("steering plugin '" + this->name() + "': no command");
  if (knuckles_.empty()) throw Error("steering plugin '" + this->name() + "': no knuckles listed");
}

SteeringPlugin::SteeringPlugin(std::string name, std::string chassisBody, std::vector<std::string> knuckles,
                               const SteeringStateSpec& state, SimTK::UnitVec3 spinAxis_K)
    : ConstraintPlugin("steering", std::move(name)),
      chassis_(std::move(chassisBody)),
      knuckles_(std::move(knuckles)),
      spin_K_(spinAxis_K),
      stateDriven_(true),
      state_(state) {
  state_.validate("steering plugin '" + this->name() + "'");
  if (knuckles_.empty()) throw Error("steering plugin '" + this->name() + "': no knuckles listed");
}

const SteeringCommand& SteeringPlugin::command() const {
  if (!command_) throw Error("steering plugin '" + name() + "' is state-driven: it has no time command");
  return *command_;
}

std::vector<std::string> SteeringPlugin::DoGetAdjustables() const {
  if (dynamic_cast<const HoldCommand*>(command_.get())) return {"angle_rad"};
  return {};
}

void SteeringPlugin::DoSetAdjustable(SimTK::State& state, const std::string&, double value) const {
  // The command is a model parameter shared with whoever made it (non-const there).
  const_cast<HoldCommand&>(dynamic_cast<const HoldCommand&>(*command_)).setAngle(value);
  state.invalidateAllCacheAtOrAbove(SimTK::Stage::Position);
}

void SteeringPlugin::DoSetAccelerationLaw(std::shared_ptr<const SteeringLaw> law) {
  if (!stateDriven_)
    throw Error("steering plugin '" + name() + "' follows a time command; a law needs a state-driven plugin");
  if (!law) throw Error("steering plugin '" + name() + "': empty acceleration law");
  if (slot_->law)
    throw Error("steering plugin '" + name() + "' already has the law '" + slot_->law->name() + "'; cannot add '" +
                law->name() + "'");
  slot_->law = std::move(law);
}

bool SteeringPlugin::DoHasAccelerationLaw() const { return slot_->law != nullptr; }

double SteeringPlugin::DoGetAngle(const SimTK::State& s) const {
  if (drivesRack()) return rackBody_.getOneQ(s, 0) / k_;
  return steer_.getAngle(s);
}

double SteeringPlugin::DoGetRate(const SimTK::State& s) const {
  if (drivesRack()) return rackBody_.getOneU(s, 0) / k_;
  return steer_.getRate(s);
}

void SteeringPlugin::driveRack(std::string rackBody, std::string commandAngle) {
  if (rackBody.empty()) throw Error("steering plugin '" + name() + "': empty rack name");
  if (commandAngle != "road_wheel" && commandAngle != "steering_wheel")
    throw Error("steering plugin '" + name() + "': command_angle must be \"road_wheel\" or \"steering_wheel\", got \"" +
                commandAngle + "\"");
  rack_ = std::move(rackBody);
  commandAngle_ = std::move(commandAngle);
}

SimTK::MobilizedBodyIndex SteeringPlugin::stateBodyIndex() const {
  assert(stateDriven_);
  return drivesRack() ? rackBody_.getMobilizedBodyIndex() : steer_.getMobilizedBodyIndex();
}

double SteeringPlugin::LawSlot::calcAcceleration(const SimTK::State& s, const std::string& who) const {
  if (external.solved && external.solved(s)) return external.acceleration(s);
  if (!law) throw Error("steering plugin '" + who + "': no acceleration law");
  return law->calcAcceleration(s);
}

double SteeringPlugin::DoCalcAcceleration(const SimTK::State& s) const { return slot_->calcAcceleration(s, name()); }

const SimTK::MobilizedBody::Pin& SteeringPlugin::getSteerBody() const {
  assert(stateDriven_);
  return steer_;
}

void SteeringPlugin::DoInitialize(const Scene&, SimTK::State&) const {
  if (stateDriven_ && !slot_->law)
    throw Error("steering plugin '" + name() + "' is state-driven but no controller set its acceleration law");
}

void SteeringPlugin::addStateDriven(Scene& scene) {
  SimTK::MobilizedBody& chassis = const_cast<SimTK::MobilizedBody&>(scene.getBody(chassis_));
  // The steer body: a Pin about the chassis zeta axis (Simbody's Pin turns
  // about z), so q = delta (+ left) and u = delta'.
  const double I = state_.steer_body_inertia_kg_m2;
  const SimTK::Body::Rigid body(SimTK::MassProperties(1e-3, Vec3(0), SimTK::Inertia(I)));
  steer_ = SimTK::MobilizedBody::Pin(chassis, SimTK::Transform(), body, SimTK::Transform());
  steer_.setDefaultAngle(state_.initial_angle_rad);
  const std::string who = name();
  // The Motion belongs to the steer body, and the law holds handles to that
  // body: a strong reference here would be a cycle that keeps the whole Simbody
  // system alive (LeakSanitizer). The plugin (owned by the scene) owns the slot.
  const std::weak_ptr<LawSlot> weakSlot = slot_;
  SimTK::Motion::Custom(steer_, new SteeringLawMotion([weakSlot, who](const SimTK::State& s) {
    const auto slot = weakSlot.lock();
    if (!slot) throw Error("steering plugin '" + who + "': no acceleration law");
    return slot->calcAcceleration(s, who);
  }));
  scene.addBody(name() + ".steer", steer_);
  for (const auto& k : knuckles_)
    SimTK::Constraint::Custom(
        new SteeringStateConstraintImpl(scene.updMatter(), chassis, scene.getBody(k), spin_K_, steer_));
  const auto slot = slot_;  // (outputs are the scene's, not the system's: no cycle)
  const SimTK::MobilizedBody::Pin steer = steer_;
  const SimTK::MobilizedBody ch = chassis, first = scene.getBody(knuckles_.front());
  const SimTK::UnitVec3 axis = spin_K_;
  scene.addOutput({name() + ".command_rad", "rad", SimTK::Stage::Position,
                   [steer](const SimTK::State& s) { return steer.getAngle(s); }});
  scene.addOutput({name() + ".rate_rad_s", "rad/s", SimTK::Stage::Velocity,
                   [steer](const SimTK::State& s) { return steer.getRate(s); }});
  // Stage::Dynamics: where the vehicle's dense rows solve delta'' it is known
  // once forces are (ExternalSolve); a law that reads a station's
  // acceleration needs Stage::Acceleration elsewhere (it says so).
  scene.addOutput({name() + ".accel_rad_s2", "rad/s^2", SimTK::Stage::Dynamics,
                   [slot, who](const SimTK::State& s) { return slot->calcAcceleration(s, who); }});
  scene.addOutput({name() + ".angle_rad", "rad", SimTK::Stage::Position,
                   [ch, first, axis](const SimTK::State& s) { return steeringAngle(s, ch, first, axis); }});
  // The wheel's angle against its integrated state: what an acceleration-only
  // command would let drift, here held by the constraint (per first knuckle).
  scene.addOutput({name() + ".drift_rad", "rad", SimTK::Stage::Position, [ch, first, axis, steer](const SimTK::State& s) {
                     return steeringAngle(s, ch, first, axis) - steer.getAngle(s);
                   }});
}

void SteeringPlugin::addRack(Scene& scene) {
  const SteeringRack rack = *scene.getService<const SteeringRack>(rack_);
  const double c = rack.travel_per_pinion_rad_m, N0 = rack.overall_ratio;
  k_ = commandAngle_ == "road_wheel" ? c * N0 : c;
  if (!std::isfinite(k_) || k_ == 0)
    throw Error("steering plugin '" + name() + "': rack '" + rack_ + "' has c = " + formatValue(c) + " m/rad, N0 = " +
                formatValue(N0) + " (no finite non-zero rack travel per command radian)");
  rackBody_ = scene.getBody(rack.body);
  SimTK::MobilizedBody::Slider& slider =
      SimTK::MobilizedBody::Slider::updDowncast(const_cast<SimTK::MobilizedBody&>(scene.getBody(rack.body)));
  const double limit = rack.travel_limit_m, k = k_;
  const std::string who = name();
  if (stateDriven_) {
    const double x0 = k * state_.initial_angle_rad;
    if (!(std::abs(x0) <= limit))
      throw Error("steering plugin '" + who + "': initial_rad " + formatValue(state_.initial_angle_rad) +
                  " asks a rack travel of " + formatValue(x0) + " m, beyond rack_travel_limit_m " + formatValue(limit));
    slider.setDefaultQ(x0);
    const std::weak_ptr<LawSlot> weakSlot = slot_;
    const SimTK::MobilizedBody rb = slider;
    SimTK::Motion::Custom(slider, new SteeringLawMotion([weakSlot, who, k, rb, limit](const SimTK::State& s) {
      const auto slot = weakSlot.lock();
      if (!slot || !slot->law) throw Error("steering plugin '" + who + "': no acceleration law");
      // The law's integrated rack travel past the rack's limit: the mechanism ends there.
      if (!(std::abs(rb.getOneQ(s, 0)) <= limit))
        throw Error("steering plugin '" + who + "': the law '" + slot->law->name() + "' drove the rack to " +
                    formatValue(rb.getOneQ(s, 0)) + " m at t = " + formatValue(s.getTime()) +
                    " s, beyond rack_travel_limit_m " + formatValue(limit));
      return k * slot->law->calcAcceleration(s);
    }));
  } else {
    const double x0 = k * command_->calcAt(0).angle_rad;
    if (!(std::abs(x0) <= limit))
      throw Error("steering plugin '" + who + "': the command at t = 0 asks a rack travel of " + formatValue(x0) +
                  " m, beyond rack_travel_limit_m " + formatValue(limit));
    slider.setDefaultQ(x0);
    SimTK::Constraint::Custom(new RackCommandConstraintImpl(scene.updMatter(), slider, k, limit, command_, who));
  }
  const SimTK::MobilizedBody r = rackBody_;
  const SimTK::MobilizedBody chassis = scene.getBody(chassis_);
  std::vector<SimTK::MobilizedBody> knuckles;
  for (const auto& kn : knuckles_) knuckles.push_back(scene.getBody(kn));
  const SimTK::UnitVec3 axis = spin_K_;
  if (stateDriven_) {
    const auto slot = slot_;
    scene.addOutput({name() + ".command_rad", "rad", SimTK::Stage::Position,
                     [r, k](const SimTK::State& s) { return r.getOneQ(s, 0) / k; }});
    scene.addOutput({name() + ".rate_rad_s", "rad/s", SimTK::Stage::Velocity,
                     [r, k](const SimTK::State& s) { return r.getOneU(s, 0) / k; }});
    scene.addOutput({name() + ".accel_rad_s2", "rad/s^2", SimTK::Stage::Velocity, [slot, who](const SimTK::State& s) {
                       if (!slot->law) throw Error("steering plugin '" + who + "': no acceleration law");
                       return slot->law->calcAcceleration(s);
                     }});
  } else {
    const auto cmd = command_;
    scene.addOutput({name() + ".command_rad", "rad", SimTK::Stage::Time,
                     [cmd](const SimTK::State& s) { return cmd->calc(s).angle_rad; }});
  }
  scene.addOutput({name() + ".angle_rad", "rad", SimTK::Stage::Position, [chassis, knuckles, axis](const SimTK::State& s) {
                     double sum = 0;
                     for (const auto& kn : knuckles) sum += headingAngle(s, chassis, kn, axis);
                     return sum / double(knuckles.size());
                   }});
  scene.addOutput({name() + ".rack_travel_m", "m", SimTK::Stage::Position,
                   [r](const SimTK::State& s) { return r.getOneQ(s, 0); }});
  scene.addOutput({name() + ".steering_wheel_rad", "rad", SimTK::Stage::Position,
                   [r, c](const SimTK::State& s) { return r.getOneQ(s, 0) / c; }});
  for (std::size_t i = 0; i < knuckles_.size(); ++i) {
    const std::string& kn = knuckles_[i];
    const std::string corner = kn.substr(0, kn.find('.'));
    const SimTK::MobilizedBody b = knuckles[i];
    scene.addOutput({name() + "." + corner + "_angle_rad", "rad", SimTK::Stage::Position,
                     [chassis, b, axis](const SimTK::State& s) { return headingAngle(s, chassis, b, axis); }});
  }
}

void SteeringPlugin::DoAddTo(Scene& scene) {
  if (drivesRack()) {
    addRack(scene);
    return;
  }
  if (stateDriven_) {
    addStateDriven(scene);
    return;
  }
  const SimTK::MobilizedBody& chassis = scene.getBody(chassis_);
  for (const auto& k : knuckles_)
    SimTK::Constraint::Custom(
        new SteeringConstraintImpl(scene.updMatter(), chassis, scene.getBody(k), spin_K_, command_));
  const auto cmd = command_;
  scene.addOutput({name() + ".command_rad", "rad", SimTK::Stage::Time,
                   [cmd](const SimTK::State& s) { return cmd->calc(s).angle_rad; }});
  const SimTK::MobilizedBody first = scene.getBody(knuckles_.front());
  const SimTK::UnitVec3 axis = spin_K_;
  scene.addOutput({name() + ".angle_rad", "rad", SimTK::Stage::Position,
                   [chassis, first, axis](const SimTK::State& s) { return steeringAngle(s, chassis, first, axis); }});
}

std::vector<SimTK::MobilizedBodyIndex> steeringStateBodies(const Scene& scene) {
  std::vector<SimTK::MobilizedBodyIndex> bodies;
  for (const auto& p : scene.getPlugins())
    if (const auto* st = dynamic_cast<const SteeringPlugin*>(p.get()); st && st->isStateDriven())
      bodies.push_back(st->stateBodyIndex());
  return bodies;
}

namespace {
/// The keys of a "steering" plugin entry (one table: read, documented by `vdyn list`).
struct SteeringEntry {
  const PluginRegistry* registry = nullptr;  ///< where the command's type is looked up
  std::string chassis = "chassis";
  std::vector<std::string> knuckles;
  Vec3 spin_axis{0, 1, 0};
  std::shared_ptr<const SteeringCommand> command;
  bool state_driven = false;
  double initial_rad = 0;
  std::string command_angle;  ///< empty: not given ("road_wheel" on a rack)
};

const FieldTable<SteeringEntry>& steeringFields() {
  static const auto t =
      FieldTable<SteeringEntry>()
          .string("chassis", &SteeringEntry::chassis, "chassis body (bindable)")
          .strings("knuckles", &SteeringEntry::knuckles,
                   "knuckle bodies steered together, e.g. [\"rf.knuckle\", \"lf.knuckle\"] (bindable: attach an axle)")
          .sample("[\"rf.knuckle\"]")
          .vec3("spin_axis", &SteeringEntry::spin_axis, "-", "wheel spin axis in the knuckle frame (bindable)")
          .custom("command", "-", "required",
                  "{type: a steering_command (hold, smooth_step, steps, ...: `vdyn list steering_command`) with "
                  "its keys | state (initial_rad: a controller sets delta'')}; rad, + left",
                  [](const ParamReader& r, SteeringEntry& e) {
                    const ParamReader c = r.child("command");
                    if (c.stringOr("type", "") == "state") {
                      e.state_driven = true;
                      e.initial_rad = c.numberOr("initial_rad", 0.0);
                    } else {
                      e.command = makeSteeringCommand(c, e.registry);
                    }
                  })
          .sample("{\"type\": \"hold\"}")
          .string("command_angle", &SteeringEntry::command_angle,
                  "on a rack axle (bound \"rack\"): road_wheel (default: the command is a road-wheel angle, the "
                  "steering-wheel angle N0 times it) | steering_wheel (the command is the steering-wheel angle); "
                  "rad, + left");
  return t;
}

Vec3 parseAxis(const std::string& text, const std::string& where) {
  std::istringstream in(text);
  Vec3 a;
  if (!(in >> a[0] >> a[1] >> a[2])) throw Error(where + ": spin_axis binding '" + text + "': expected 3 numbers");
  return a;
}

}  // namespace

void registerSteeringPlugins(PluginRegistry& registry) {
  registerSteeringCommands(registry);
  registry.add(
      PluginKind::Constraint, "steering",
      [](const PluginSpec& spec) -> std::unique_ptr<Plugin> {
        SteeringEntry e;
        e.registry = spec.registry;
        steeringFields().read(spec.params, e);
        if (spec.bindings.count("chassis")) e.chassis = spec.bindings.at("chassis");
        if (spec.bindings.count("knuckles")) e.knuckles = splitList(spec.bindings.at("knuckles"));
        if (spec.bindings.count("spin_axis")) e.spin_axis = parseAxis(spec.bindings.at("spin_axis"), spec.params.where());
        if (e.knuckles.empty()) throw Error(spec.params.at("knuckles") + ": no knuckles (list them or attach an axle)");
        const SimTK::UnitVec3 spin(e.spin_axis);
        std::unique_ptr<SteeringPlugin> p;
        if (e.state_driven) {
          SteeringStateSpec st;
          st.initial_angle_rad = e.initial_rad;
          p = std::make_unique<SteeringPlugin>(spec.name, e.chassis, e.knuckles, st, spin);
        } else {
          p = std::make_unique<SteeringPlugin>(spec.name, e.chassis, e.knuckles, e.command, spin);
        }
        if (spec.bindings.count("rack")) {
          try {
            p->driveRack(spec.bindings.at("rack"), e.command_angle.empty() ? "road_wheel" : e.command_angle);
          } catch (const Error& err) {
            throw Error(spec.params.at("command_angle") + ": " + err.what());
          }
        } else if (!e.command_angle.empty()) {
          throw Error(spec.params.at("command_angle") + ": only a steering on a rack axle (attach an axle with a "
                      "\"steering\" rack) takes a command_angle");
        }
        return p;
      },
      typeInfo("steering angle of knuckles (A.1)-(A.4) held on a time command (holonomic constraint) or "
               "state-driven by a controller; outputs <name>.angle_rad, <name>.command_rad",
               steeringFields()));
}

}  // namespace vdyn
