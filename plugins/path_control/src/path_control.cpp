#include "vdyn/path_control/path_control.h"

#include "vdyn/core/fields.h"
#include "vdyn/rear_steer/rear_steer.h"

#include <algorithm>
#include <cmath>
#include <functional>

namespace vdyn {

using SimTK::Vec2;
using SimTK::Vec3;

void PathControlParams::validate() const {
  requireNonNegative(k1_rad_per_s2_per_m, "path control k1_rad_per_s2_per_m");
  requireNonNegative(k2_rad_per_s2, "path control k2_rad_per_s2");
  requireNonNegative(k3_rad_per_s2_per_m, "path control k3_rad_per_s2_per_m");
  requireNonNegative(k4_rad_per_s2, "path control k4_rad_per_s2");
  requireNonNegative(k5_per_s, "path control k5_per_s");
  requireNonNegative(look_ahead_s, "path control look_ahead_s");
  requirePositive(acceleration_lag_s, "path control acceleration_lag_s");
  for (int i = 0; i < 3; ++i) requireFinite(tracked_point_m[i], "path control tracked_point_m");
  if (acceleration_estimate != "solved" && acceleration_estimate != "lagged" && acceleration_estimate != "none")
    throw Error("path control acceleration_estimate must be \"solved\", \"lagged\" or \"none\", got \"" +
                acceleration_estimate + "\"");
}

void PathFeedforwardParams::validate() const {
  if (type != "none" && type != "linear_bicycle")
    throw Error("path control feedforward must be \"none\" or \"linear_bicycle\", got \"" + type + "\"");
  requireNonNegative(preview_s, "path control feedforward_preview_s");
  requirePositive(lag_s, "path control feedforward_lag_s");
  requireNonNegative(yaw_rate_gain_per_s, "path control yaw_rate_gain_per_s");
  requirePositive(yaw_inertia_kg_m2, "path control yaw_inertia_kg_m2");
  if (!rear_steering.empty() && !rear_control.empty())
    throw Error("path control: feedforward_rear_steering \"" + rear_steering + "\" and feedforward_rear_control \"" +
                rear_control + "\" both set; the rear angle is either measured or the strategy's, not both");

  if (type == "linear_bicycle") {
    if (!has_linear_bicycle)
      throw Error("path control feedforward \"linear_bicycle\" needs the key linear_bicycle {mass_kg, ...}");
    linear_bicycle.validate();
  }
}

// The linear bicycle's steady turn (chapter 6, (6.5)-(6.6) with beta' = r' = 0,
// r = U kappa): delta_f - delta_r = (l + K U^2) kappa, the same relation as
// calcLinearSteadyYawRate's r = U delta_f (1 - Kr) / (l + K U^2) with
// delta_r = Kr delta_f.
double PathFeedforwardParams::calcSteadySteer(double kappa, double U, double rear,
                                             const std::function<double(double, double)>* ratio) const {
  if (type == "none") return 0;
  const double bicycle = (linear_bicycle.wheelbase_m() + linear_bicycle.understeerGradient() * U * U) * kappa;
  if (!ratio || !*ratio) return rear + bicycle;
  // The 4WS steady turn with delta_r = Kr(U, delta_f) delta_f (8.1)-(8.4):
  // delta_f (1 - Kr(U, delta_f)) = (l + K U^2) kappa, by fixed-point iteration
  // from the 2WS angle (Kr constant: one step; Kr = C1 + C2 delta_f^2: the map's
  // slope is 2 C2 delta_f^2 / (1 - Kr), 0.1-0.3 on the chapter 8 turns).
  double df = bicycle;
  for (int it = 0; it < 50; ++it) {
    const double next = bicycle / (1 - (*ratio)(U, df));
    if (!std::isfinite(next)) return bicycle;  // Kr -> 1: no steady 4WS turn; the 2WS angle
    const bool done = std::abs(next - df) <= 1e-12;
    df = next;
    if (done) break;
  }
  return df;
}

double PathFeedforwardParams::calcSteadyCurvature(double df, double U, double rear,
                                                  const std::function<double(double, double)>* ratio) const {
  if (type == "none") return 0;
  const double dr = ratio && *ratio ? (*ratio)(U, df) * df : rear;
  return (df - dr) / (linear_bicycle.wheelbase_m() + linear_bicycle.understeerGradient() * U * U);
}

const FieldTable<PathFeedforwardParams>& PathFeedforwardParams::fields() {
  using P = PathFeedforwardParams;
  static const auto t =
      FieldTable<P>()
          .string("feedforward", &P::type,
                  "steer feed-forward of the path curvature: none (the seed's law (7.17)-(7.18)) | linear_bicycle "
                  "(delta_r + (l + K U^2) kappa through the K5 damper; docs/path_feedforward.md)")
          .custom("linear_bicycle", "-", "required for linear_bicycle",
                  "{mass_kg, front_axle_to_com_m, rear_axle_to_com_m, front_/rear_cornering_stiffness_N_per_rad}: "
                  "l and K of the feed-forward",
                  [](const ParamReader& r, P& p) {
                    if (!r.has("linear_bicycle")) return;
                    p.linear_bicycle = LinearBicycleParams::fromParams(r.child("linear_bicycle"));
                    p.has_linear_bicycle = true;
                  })
          .sample("{\"mass_kg\": 1024, \"front_axle_to_com_m\": 1.305, \"rear_axle_to_com_m\": 0.965, "
                  "\"front_cornering_stiffness_N_per_rad\": 1.4e5, \"rear_cornering_stiffness_N_per_rad\": 1.4e5}")
          .number("feedforward_preview_s", &P::preview_s, "s",
                  "T_ff: the curvature is read at the path point of p + v T_ff")
          .number("feedforward_lag_s", &P::lag_s, "s", "tau_ff of each of the two first-order stages filtering delta_ss")
          .string("feedforward_rear_control", &P::rear_control,
                  "rear_steer plugin (listed before this one) whose Kr(U, delta_f) gives the 4WS steady steer "
                  "delta_f (1 - Kr) = (l + K U^2) kappa; \"\" for the 2WS one")
          .number("yaw_rate_gain_per_s", &P::yaw_rate_gain_per_s, "1/s",
                  "K_r: delta'' -= K_r (r - r_ref), r_ref the yaw rate of the linear bicycle steered by the filtered "
                  "feed-forward f (with a feedforward only: none is the seed's law)")
          .number("yaw_inertia_kg_m2", &P::yaw_inertia_kg_m2, "kg m^2", "I_z of the reference bicycle of K_r")
          .string("feedforward_rear_steering", &P::rear_steering,
                  "steering plugin whose angle is delta_r (4WS rear); \"\": none (2WS)");
  return t;
}

double calcFeedforwardTarget(const PathFeedforwardParams& ff, const ReferencePath& path, const Vec2& p_G,
                             const Vec2& v_G, double rear_rad, const std::function<double(double, double)>* ratio) {
  if (!ff.enabled()) return 0;
  const PathPoint ahead = path.calcReferencePoint(p_G + v_G * ff.preview_s);
  return ff.calcSteadySteer(ahead.curvature_per_m, v_G.norm(), rear_rad, ratio);
}

namespace {
const FieldTable<PathControlParams>& gainFields() {
  using P = PathControlParams;
  static const auto t =
      FieldTable<P>()
          .number("k1_rad_per_s2_per_m", &P::k1_rad_per_s2_per_m, "rad/s^2/m", "K1 on e1, position error now (7.17)", true)
          .number("k2_rad_per_s2", &P::k2_rad_per_s2, "rad/s^2", "K2 on e2, slope error now", true)
          .number("k3_rad_per_s2_per_m", &P::k3_rad_per_s2_per_m, "rad/s^2/m", "K3 on e3, position error at t + dT", true)
          .number("k4_rad_per_s2", &P::k4_rad_per_s2, "rad/s^2", "K4 on e4, slope error at t + dT", true)
          .number("k5_per_s", &P::k5_per_s, "1/s", "K5, damper on delta' (7.18)", true)
          .number("look_ahead_s", &P::look_ahead_s, "s", "dT of the prediction (7.13)-(7.16)", true)
          .string("acceleration_estimate", &P::acceleration_estimate, "x'' in the prediction: solved (with delta'', dense formulation) | lagged | none")
          .number("acceleration_lag_s", &P::acceleration_lag_s, "s", "lag of the measured acceleration (lagged)")
          .vec3("tracked_point_m", &P::tracked_point_m, "m", "chassis point that follows the path, chassis frame");
  return t;
}
}  // namespace

PathControlParams PathControlParams::fromParams(const ParamReader& r) {
  PathControlParams p = gainFields().read(r);
  p.validate();
  return p;
}

// ---------------------------------------------------------------------------
PathController::PathController(std::string name, const PathControlParams& params,
                               std::shared_ptr<const ReferencePath> path, const SimTK::MobilizedBody& chassis,
                               const SteeringActuator& steer, SimTK::Measure ax, SimTK::Measure ay,
                               const PathFeedforwardParams& feedforward, const SteeringActuator* rear,
                               SimTK::Measure stage1, SimTK::Measure filtered,
                               std::function<double(double, double)> rearRatio, SimTK::Measure referenceYawRate)
    : SteeringLaw(std::move(name)), p_(params), path_(std::move(path)), chassis_(chassis), steer_(&steer), ax_(ax),
      ay_(ay), ff_(feedforward), rear_(rear), stage1_(stage1), filtered_(filtered), ratio_(std::move(rearRatio)),
      yawRef_(referenceYawRate) {
  p_.validate();
  ff_.validate();
  assert(!ff_.enabled() || !filtered_.isEmptyHandle());
  if (!path_) throw Error("path controller '" + this->name() + "': no path");
  assert(p_.acceleration_estimate != "lagged" || (!ax_.isEmptyHandle() && !ay_.isEmptyHandle()));
  lagged_ = p_.acceleration_estimate == "lagged";
  solved_ = p_.acceleration_estimate == "solved";
}

bool PathController::DoGetStationAccelerationInput(StationAccelerationInput* input) const {
  if (!solved_) return false;
  if (input) *input = {chassis_.getMobilizedBodyIndex(), p_.tracked_point_m};
  return true;
}

PathControlEvaluation PathController::calcEvaluation(const SimTK::State& s, bool withTarget) const {
  if (!solved_)
    return calcEvaluationGiven(s, lagged_ ? Vec2(ax_.getValue(s), ay_.getValue(s)) : Vec2(0, 0), withTarget);
  if (s.getSystemStage() < SimTK::Stage::Acceleration)
    throw Error("path controller '" + name() + "': acceleration_estimate \"solved\" needs x'' and delta'' solved "
                "together, which the vehicle's dense forward dynamics does (formulation \"auto\" or \"dense\"); "
                "here delta'' was asked before the accelerations (t = " + formatValue(s.getTime()) +
                " s): use acceleration_estimate \"lagged\" with this formulation");
  const Vec3 a = chassis_.findStationAccelerationInGround(s, p_.tracked_point_m);
  return calcEvaluationGiven(s, Vec2(a[0], a[1]), withTarget);
}

PathControlEvaluation PathController::calcEvaluationGiven(const SimTK::State& s, const Vec2& xdd_G,
                                                          bool withTarget) const {
  PathControlEvaluation e;
  const Vec3 p = chassis_.findStationLocationInGround(s, p_.tracked_point_m),
             v = chassis_.findStationVelocityInGround(s, p_.tracked_point_m);
  e.p_G = Vec2(p[0], p[1]);
  e.v_G = Vec2(v[0], v[1]);
  e.a_G = xdd_G;
  const double rear = ff_.enabled() && rear_ ? rear_->getAngle(s) : 0.0;
  if (ff_.enabled()) {
    // The prediction (7.13)-(7.16) takes the turn the feed-forward is about to
    // steer (header): x'' plus U^2 (kappa_g - kappa_f) normal to v, the
    // curvatures of the two filter stages (g - delta_r) / (l + K U^2), ...;
    // in a steady turn they agree and x'' is the seed's.
    const double U = e.v_G.norm();
    e.feedforward_rad = filtered_.getValue(s);
    if (U > 0) {
      const double kG = ff_.calcSteadyCurvature(stage1_.getValue(s), U, rear, &ratio_),
                   kF = ff_.calcSteadyCurvature(e.feedforward_rad, U, rear, &ratio_);
      e.a_G += U * U * (kG - kF) * Vec2(-e.v_G[1], e.v_G[0]) / U;
    }
  }
  const double dT = p_.look_ahead_s;
  e.p_ahead_G = e.p_G + e.v_G * dT + e.a_G * (dT * dT / 2);  // (7.13)-(7.14)
  e.v_ahead_G = e.v_G + e.a_G * dT;                           // (7.15)-(7.16)
  e.now = path_->calcErrors(e.p_G, e.v_G);                    // e1, e2 (7.9)-(7.10), (7.19)-(7.21)
  e.ahead = path_->calcErrors(e.p_ahead_G, e.v_ahead_G);      // e3, e4
  e.steer_rate_rad_s = steer_->getRate(s);
  // (7.17) with the artificial damper (7.18).
  e.accel_rad_s2 = -(p_.k1_rad_per_s2_per_m * e.now.position_m + p_.k2_rad_per_s2 * e.now.slope +
                     p_.k3_rad_per_s2_per_m * e.ahead.position_m + p_.k4_rad_per_s2 * e.ahead.slope) -
                   p_.k5_per_s * e.steer_rate_rad_s;
  if (ff_.enabled()) {
    // The feed-forward through the damper: -K5 (delta' - f') (header, docs/path_feedforward.md).
    if (withTarget) e.feedforward_target_rad = calcFeedforwardTarget(ff_, *path_, e.p_G, e.v_G, rear, &ratio_);
    e.feedforward_rate_rad_s = (stage1_.getValue(s) - e.feedforward_rad) / ff_.lag_s;
    e.accel_rad_s2 += p_.k5_per_s * e.feedforward_rate_rad_s;
    if (!yawRef_.isEmptyHandle()) {
      // Yaw-rate feedback about the reference bicycle (header, docs/path_feedforward.md).
      e.reference_yaw_rate_rad_s = yawRef_.getValue(s);
      e.yaw_rate_error_rad_s = chassis_.getBodyAngularVelocity(s)[2] - e.reference_yaw_rate_rad_s;
      e.accel_rad_s2 -= ff_.yaw_rate_gain_per_s * e.yaw_rate_error_rad_s;
    }
  }
  return e;
}

// ---------------------------------------------------------------------------
namespace {
/// A first-order lag: a z variable with z' = (input(s) - z) / tau, its
/// value read from z directly (no cache entry: z can change without
/// Stage::Time being invalidated). The derivative is set while the force
/// subsystem realizes Acceleration, after Simbody has computed the matter's
/// accelerations, so `input` may need any stage up to Acceleration. Used for
/// the tracked point's lagged acceleration (x'' -> a) and the two stages of
/// the feed-forward filter (delta_ss -> g -> f; header).
class FirstOrderLagMeasure : public SimTK::Measure_<SimTK::Real> {
 public:
  using Input = std::function<double(const SimTK::State&)>;
  class Implementation : public SimTK::Measure_<SimTK::Real>::Implementation {
   public:
    Implementation(Input input, double tau)
        : SimTK::Measure_<SimTK::Real>::Implementation(0.0, 0), input_(std::move(input)), tau_(tau) {}
    Implementation* cloneVirtual() const override { return new Implementation(*this); }
    int getNumTimeDerivativesVirtual() const override { return 0; }
    SimTK::Stage getDependsOnStageVirtual(int) const override { return SimTK::Stage::Time; }
    const SimTK::Real& getUncachedValueVirtual(const SimTK::State& s, int derivOrder) const override {
      assert(derivOrder == 0);
      (void)derivOrder;
      return getSubsystem().getZ(s)[zIndex_];
    }
    void realizeMeasureTopologyVirtual(SimTK::State& s) const override {
      zIndex_ = getSubsystem().allocateZ(s, SimTK::Vector(1, 0.0));
    }
    void initializeVirtual(SimTK::State& s) const override { getSubsystem().updZ(s)[zIndex_] = 0; }
    void realizeMeasureAccelerationVirtual(const SimTK::State& s) const override {
      getSubsystem().updZDot(s)[zIndex_] = (input_(s) - getSubsystem().getZ(s)[zIndex_]) / tau_;
    }
    /// The integrator's error weight of z (Simbody's unit weight: a change
    /// of 1 / weight in z counts as one unit of error); the state must be
    /// realized to Stage::Model.
    void setErrorWeight(SimTK::State& s, double weight) const {
      s.updZWeights(getSubsystem().getMySubsystemIndex())[zIndex_] = weight;
    }

   private:
    Input input_;
    double tau_;
    mutable SimTK::ZIndex zIndex_;
  };
  FirstOrderLagMeasure(SimTK::Subsystem& sub, Input input, double tau)
      : SimTK::Measure_<SimTK::Real>(sub, new Implementation(std::move(input), tau),
                                     SimTK::AbstractMeasure::SetHandle()) {}
  void setErrorWeight(SimTK::State& s, double weight) const {
    static_cast<const Implementation&>(getImpl()).setErrorWeight(s, weight);
  }
};

/// The reference model of the yaw-rate feedback: the linear bicycle ((6.5)-(6.6),
/// chapter 6) at the speed U(s), steered by delta_f(s) and delta_r(s), two z
/// variables (v, r) with
///     M (v' + U r) = F_f + F_r,   I_z r' = a F_f - b F_r,
///     F_f = C_af (delta_f - (v + a r) / U),   F_r = C_ar (delta_r - (v - b r) / U);
/// its value is r. Set like FirstOrderLagMeasure's (Stage::Acceleration).
class ReferenceBicycleMeasure : public SimTK::Measure_<SimTK::Real> {
 public:
  /// Speed U, front and rear angles of a state.
  using Inputs = std::function<void(const SimTK::State&, double& U, double& df, double& dr)>;
  class Implementation : public SimTK::Measure_<SimTK::Real>::Implementation {
   public:
    Implementation(Inputs in, LinearBicycleParams p, double iz)
        : SimTK::Measure_<SimTK::Real>::Implementation(0.0, 0), in_(std::move(in)), p_(p), iz_(iz) {}
    Implementation* cloneVirtual() const override { return new Implementation(*this); }
    int getNumTimeDerivativesVirtual() const override { return 0; }
    SimTK::Stage getDependsOnStageVirtual(int) const override { return SimTK::Stage::Time; }
    const SimTK::Real& getUncachedValueVirtual(const SimTK::State& s, int) const override {
      return getSubsystem().getZ(s)[zIndex_ + 1];
    }
    void realizeMeasureTopologyVirtual(SimTK::State& s) const override {
      zIndex_ = getSubsystem().allocateZ(s, SimTK::Vector(2, 0.0));
    }
    void initializeVirtual(SimTK::State& s) const override {
      getSubsystem().updZ(s)[zIndex_] = getSubsystem().updZ(s)[zIndex_ + 1] = 0;
    }
    void realizeMeasureAccelerationVirtual(const SimTK::State& s) const override {
      double U = 0, df = 0, dr = 0;
      in_(s, U, df, dr);
      const double v = getSubsystem().getZ(s)[zIndex_], r = getSubsystem().getZ(s)[zIndex_ + 1];
      double vd = 0, rd = 0;
      if (U > 0.1) {
        const double a = p_.front_axle_to_com_m, b = p_.rear_axle_to_com_m;
        const double Ff = p_.front_cornering_stiffness_N_per_rad * (df - (v + a * r) / U),
                     Fr = p_.rear_cornering_stiffness_N_per_rad * (dr - (v - b * r) / U);
        vd = (Ff + Fr) / p_.mass_kg - U * r;
        rd = (a * Ff - b * Fr) / iz_;
      }
      getSubsystem().updZDot(s)[zIndex_] = vd;
      getSubsystem().updZDot(s)[zIndex_ + 1] = rd;
    }

   private:
    Inputs in_;
    LinearBicycleParams p_;
    double iz_;
    mutable SimTK::ZIndex zIndex_;
  };
  ReferenceBicycleMeasure(SimTK::Subsystem& sub, Inputs in, const LinearBicycleParams& p, double iz)
      : SimTK::Measure_<SimTK::Real>(sub, new Implementation(std::move(in), p, iz),
                                     SimTK::AbstractMeasure::SetHandle()) {}
};

/// One horizontal component (axis 0: x, 1: y) of the tracked point's
/// acceleration in Ground through a first-order lag: a' = (x'' - a) / tau.
FirstOrderLagMeasure addLaggedAcceleration(Scene& scene, const SimTK::MobilizedBody& chassis, const Vec3& station, int axis,
                                     double tau) {
  // The body by index, not by handle: a (reference-counted) handle held by a
  // measure of the same system kept the whole system alive (LeakSanitizer).
  const SimTK::SimbodyMatterSubsystem* matter = &chassis.getMatterSubsystem();
  const SimTK::MobilizedBodyIndex body = chassis.getMobilizedBodyIndex();
  return FirstOrderLagMeasure(
      scene.updForces(),
      [matter, body, station, axis](const SimTK::State& s) {
        return matter->getMobilizedBody(body).findStationAccelerationInGround(s, station)[axis];
      },
      tau);
}
}  // namespace

PathControlPlugin::PathControlPlugin(std::string name, std::string steeringPlugin, std::string chassisBody,
                                     std::shared_ptr<const ReferencePath> path, const PathControlParams& params,
                                     const PathFeedforwardParams& feedforward)
    : ControllerPlugin("path_control", std::move(name)),
      steering_(std::move(steeringPlugin)),
      chassis_(std::move(chassisBody)),
      path_(std::move(path)),
      p_(params),
      ff_(feedforward) {
  p_.validate();
  ff_.validate();
  if (!path_) throw Error("path control plugin '" + this->name() + "': no path");
}

const PathController& PathControlPlugin::controller() const {
  if (!law_) throw Error("path control plugin '" + name() + "' is not added to a scene yet");
  return *law_;
}

void PathControlPlugin::DoAddDecorations(SceneDecorations& decorations) const {
  SceneDecorations::Line line{name() + ".path", {}};
  for (const PathPoint& p : path_->sample(20.0, 40.0, 0.5)) line.p_G.push_back({p.p_G[0], p.p_G[1], 0.0});
  decorations.lines.push_back(std::move(line));
}

void PathControlPlugin::DoInitialize(const Scene&, SimTK::State& state) const {
  if (setErrorWeights_) setErrorWeights_(state);
}

void PathControlPlugin::DoAddTo(Scene& scene) {
  auto* steer = scene.findPlugin<SteeringActuator>(steering_);
  if (!steer) throw Error("path control plugin '" + name() + "': the scene has no steering plugin '" + steering_ + "'");
  if (!steer->isStateDriven())
    throw Error("path control plugin '" + name() + "': steering plugin '" + steering_ +
                "' follows a time command; the controller needs a state-driven one");
  const SimTK::MobilizedBody& chassis = scene.getBody(chassis_);
  SimTK::Measure ax, ay;
  if (p_.acceleration_estimate == "lagged") {
    const FirstOrderLagMeasure lx = addLaggedAcceleration(scene, chassis, p_.tracked_point_m, 0, p_.acceleration_lag_s);
    const FirstOrderLagMeasure ly = addLaggedAcceleration(scene, chassis, p_.tracked_point_m, 1, p_.acceleration_lag_s);
    ax = lx;
    ay = ly;
    // lagged_error_weight: a enters (7.13)-(7.16) only as the predicted
    // position's a dT^2 / 2, so an error in a counts as that much position
    // error: weight dT^2 / 2 (m per m/s^2), one unit of weighted error being
    // one metre of prediction, as for the chassis's own coordinates. With
    // Simbody's default weight 1 (1 m/s^2 of a as one unit), the error
    // control of a itself held the chapter 8 runs to 1.4-1.6 times the steps
    // at the same path errors; now the lane changes reach the stability bound
    // of the lag's mode (-1 / tau; docs/benchmarks.md, "Closed loops").
    const double w = 0.5 * p_.look_ahead_s * p_.look_ahead_s;
    if (w > 0)
      setErrorWeights_ = [lx, ly, w](SimTK::State& s) {
        lx.setErrorWeight(s, w);
        ly.setErrorWeight(s, w);
      };
  }
  const SteeringActuator* rear = nullptr;
  SimTK::Measure stage1, filtered;
  std::function<double(double, double)> ratio;
  SimTK::Measure yawRef;
  if (ff_.enabled()) {
    if (!ff_.rear_steering.empty()) {
      rear = scene.findPlugin<SteeringActuator>(ff_.rear_steering);
      if (!rear)
        throw Error("path control plugin '" + name() + "': feedforward_rear_steering: the scene has no steering plugin '" +
                    ff_.rear_steering + "'");
    }
    if (!ff_.rear_control.empty()) {
      const auto* rc = scene.findPlugin<RearSteerPlugin>(ff_.rear_control);
      if (!rc)
        throw Error("path control plugin '" + name() + "': feedforward_rear_control: no rear_steer plugin '" +
                    ff_.rear_control + "' before it in the scene (list it before '" + name() + "')");
      const std::shared_ptr<const RearSteerStrategy> st = rc->strategyHandle();
      ratio = [st](double U, double df) { return st->calcTarget(U, df, 0, 0).kr; };
    }
    // Two first-order stages g, f (a critically damped second-order filter):
    // f' = (g - f) / tau_ff is continuous where delta_ss steps.
    const SimTK::SimbodyMatterSubsystem* matter = &chassis.getMatterSubsystem();  // by index (addLaggedAcceleration)
    const SimTK::MobilizedBodyIndex body = chassis.getMobilizedBodyIndex();
    const Vec3 station = p_.tracked_point_m;
    const std::shared_ptr<const ReferencePath> path = path_;
    const PathFeedforwardParams ff = ff_;
    stage1 = FirstOrderLagMeasure(
        scene.updForces(),
        [matter, body, station, path, ff, rear, ratio](const SimTK::State& s) {  // delta_ss (needs Stage::Velocity)
          const SimTK::MobilizedBody& b = matter->getMobilizedBody(body);
          const Vec3 p = b.findStationLocationInGround(s, station), v = b.findStationVelocityInGround(s, station);
          return calcFeedforwardTarget(ff, *path, Vec2(p[0], p[1]), Vec2(v[0], v[1]), rear ? rear->getAngle(s) : 0.0,
                                       &ratio);
        },
        ff_.lag_s);
    filtered = FirstOrderLagMeasure(
        scene.updForces(), [stage1](const SimTK::State& s) { return stage1.getValue(s); }, ff_.lag_s);
    if (ff_.yaw_rate_gain_per_s > 0) {
      // The reference bicycle steered by f and its rear angle (Kr(U, f) f, the
      // measured delta_r, or 0), at the tracked point's speed.
      const SimTK::Measure f = filtered;
      yawRef = ReferenceBicycleMeasure(
          scene.updForces(),
          [matter, body, station, f, rear, ratio](const SimTK::State& s, double& U, double& df, double& dr) {
            const Vec3 v = matter->getMobilizedBody(body).findStationVelocityInGround(s, station);
            U = std::sqrt(v[0] * v[0] + v[1] * v[1]);
            df = f.getValue(s);
            dr = ratio ? ratio(U, df) * df : rear ? rear->getAngle(s) : 0.0;
          },
          ff_.linear_bicycle, ff_.yaw_inertia_kg_m2);
    }
  }
  law_ = std::make_shared<PathController>(name(), p_, path_, chassis, *steer, ax, ay, ff_, rear, stage1, filtered,
                                          ratio, yawRef);
  steer->setAccelerationLaw(law_);
  const auto law = law_;
  // Outputs of what x'' moves (e3, e4, x'' itself) need Stage::Acceleration
  // with the "solved" estimate; the others are read with x'' = 0 there.
  const bool solved = p_.acceleration_estimate == "solved";
  // `target`: the output reads delta_ss (only feedforward_target_rad's evaluation solves for it).
  auto add = [&](const std::string& key, const std::string& unit, bool readsXdd, auto f, bool target = false) {
    if (solved && !readsXdd)
      scene.addOutput({name() + "." + key, unit, SimTK::Stage::Velocity, [law, f, target](const SimTK::State& s) {
                         return f(law->calcEvaluationGiven(s, Vec2(0, 0), target));
                       }});
    else
      scene.addOutput({name() + "." + key, unit, solved ? SimTK::Stage::Acceleration : SimTK::Stage::Velocity,
                       [law, f, target](const SimTK::State& s) { return f(law->calcEvaluation(s, target)); }});
  };
  add("e1_m", "m", false, [](const PathControlEvaluation& e) { return e.now.position_m; });
  add("e2", "1", false, [](const PathControlEvaluation& e) { return e.now.slope; });
  add("e3_m", "m", true, [](const PathControlEvaluation& e) { return e.ahead.position_m; });
  add("e4", "1", true, [](const PathControlEvaluation& e) { return e.ahead.slope; });
  add("feedforward_rad", "rad", false, [](const PathControlEvaluation& e) { return e.feedforward_rad; });
  add("feedforward_target_rad", "rad", false, [](const PathControlEvaluation& e) { return e.feedforward_target_rad; },
      true);
  add("reference_yaw_rate_rad_s", "rad/s", false,
      [](const PathControlEvaluation& e) { return e.reference_yaw_rate_rad_s; });
  // The estimated (or solved) acceleration's component normal to the velocity (+ left).
  add("lateral_acceleration_m_s2", "m/s^2", true, [](const PathControlEvaluation& e) {
    const double v = e.v_G.norm();
    return v > 0 ? (e.v_G[0] * e.a_G[1] - e.v_G[1] * e.a_G[0]) / v : 0.0;
  });
  const auto path = path_;
  const SimTK::MobilizedBody ch = chassis;
  const Vec3 station = p_.tracked_point_m;
  scene.addOutput({name() + ".path_distance_m", "m", SimTK::Stage::Position, [path, ch, station](const SimTK::State& s) {
                     const Vec3 p = ch.findStationLocationInGround(s, station);
                     return path->calcDistance(Vec2(p[0], p[1]));
                   }});
}

namespace {
/// The keys of a "path_control" plugin entry (one table: read, documented by `vdyn list`).
struct PathControlEntry {
  std::string steering, chassis;
  std::shared_ptr<const ReferencePath> path;
  PathControlParams gains;
  PathFeedforwardParams feedforward;
};
const FieldTable<PathControlEntry>& pathControlFields() {
  using E = PathControlEntry;
  static const auto t =
      FieldTable<E>()
          .custom("steering", "-", "required", "name of the state-driven steering plugin it drives (bindable)",
                  [](const ParamReader& r, E& e) { if (r.has("steering")) e.steering = r.string("steering"); })
          .sample("\"front_steer\"")
          .custom("chassis", "-", "required", "chassis body (bindable: attach chassis)",
                  [](const ParamReader& r, E& e) { if (r.has("chassis")) e.chassis = r.string("chassis"); })
          .sample("\"chassis\"")
          .custom("path", "-", "required",
                  "reference path {type: lane_change (7.6)-(7.8) | j_turn (7.19)-(7.24) | double_lane_change, ...}",
                  [](const ParamReader& r, E& e) { e.path = makeReferencePath(r.child("path")); })
          .sample("{\"type\": \"lane_change\", \"length_m\": 30, \"shift_m\": 3}")
          .object("gains", &E::gains, gainFields(), "gains and look-ahead", true)
          .include(&E::feedforward, PathFeedforwardParams::fields());
  return t;
}
}  // namespace

SwingDecay calcSwingDecay(const std::vector<double>& t, const std::vector<double>& x, double t0, double t1,
                          double floor) {
  if (t.size() != x.size()) throw Error("calcSwingDecay: time and value columns differ in length");
  std::vector<double> ext, tExt;
  for (std::size_t i = 1; i + 1 < x.size(); ++i)
    if (t[i] >= t0 && t[i] <= t1 && (x[i] - x[i - 1]) * (x[i + 1] - x[i]) < 0) ext.push_back(x[i]), tExt.push_back(t[i]);
  // 1. A pair of extremes closer than the floor is an inflection's wiggle or
  //    noise, not a swing: drop both and merge what is left into alternating
  //    extremes (a run of maxima keeps its largest, of minima its smallest).
  for (bool changed = true; changed;) {
    changed = false;
    for (std::size_t k = 0; k + 1 < ext.size(); ++k)
      if (std::abs(ext[k + 1] - ext[k]) <= floor) {
        ext.erase(ext.begin() + k, ext.begin() + k + 2), tExt.erase(tExt.begin() + k, tExt.begin() + k + 2);
        changed = true;
        break;
      }
    for (std::size_t k = 1; k + 1 < ext.size(); ++k)
      if ((ext[k] - ext[k - 1]) * (ext[k + 1] - ext[k]) > 0) {  // k is no extreme any more
        ext.erase(ext.begin() + k), tExt.erase(tExt.begin() + k);
        changed = true;
        break;
      }
  }
  std::vector<double> a;
  for (std::size_t k = 0; k + 1 < ext.size(); ++k) a.push_back(std::abs(ext[k + 1] - ext[k]));
  // 2. The free decay starts at the largest half-swing (those before it are
  //    still forced: the turn's entry), and 3. ends before a half-swing that
  //    grows (a second, slower motion, or the exit's look-ahead).
  SwingDecay d;
  if (a.empty()) return d;
  const std::size_t k0 = std::size_t(std::max_element(a.begin(), a.end()) - a.begin());
  d.first_extreme_time_s = tExt[k0];
  for (std::size_t k = k0; k < a.size(); ++k) {
    if (k > k0 && a[k] > a[k - 1]) break;
    d.amplitudes.push_back(a[k]);
  }
  d.half_swings = int(d.amplitudes.size());
  if (d.half_swings < 2) return d;
  const int n = d.half_swings;
  const double dec = 2 * std::log(d.amplitudes.front() / d.amplitudes.back()) / (n - 1);
  d.zeta = dec / std::sqrt(4 * SimTK::Pi * SimTK::Pi + dec * dec);
  d.frequency_hz = 1 / (2 * (tExt[k0 + n] - tExt[k0]) / n);
  return d;
}

void registerPathControlPlugins(PluginRegistry& registry) {
  registry.add(
      PluginKind::Controller, "path_control",
      [](const PluginSpec& spec) -> std::unique_ptr<Plugin> {
        PathControlEntry e = pathControlFields().read(spec.params);
        e.gains.validate();
        try {
          e.feedforward.validate();
        } catch (const Error& err) {
          throw Error(spec.params.where() + ": " + err.what());
        }
        return std::make_unique<PathControlPlugin>(spec.name, spec.bound("steering"), spec.bound("chassis"), e.path,
                                                   e.gains, e.feedforward);
      },
      typeInfo("path-following steering law (7.9)-(7.18) with look-ahead, optional curvature feed-forward; outputs "
               "<name>.e1_m, ...",
               pathControlFields()));
}

}  // namespace vdyn
