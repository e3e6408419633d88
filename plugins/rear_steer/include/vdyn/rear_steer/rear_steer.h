#pragma once
// Rear-steer strategies of chapter 8 (docs/equations.md, "Rear steer"): the rear
// steering angle follows a target delta_r* = f(delta_f) set by the steering
// angle ratio Kr = delta_r / delta_f, and its acceleration is commanded as
//     delta_r'' = delta_r*'' + G1 (delta_r* - delta_r) + G2 (delta_r*' - delta_r')   (8.5), (8.8)
// with delta_r*' and delta_r*'' from the front angle's rate and acceleration
// (the front's path controller output). Strategies:
//   2ws        delta_r* = 0 (conventional front steering);
//   linear     delta_r* = Kr(U) delta_f, Kr of the linear bicycle at the
//              current speed U (zero steady side slip)              (8.2)-(8.4)
//   nonlinear  Kr = C1 + C2 delta_f^2 (delta_f in degrees) (8.1), C1 and C2
//              interpolated in speed from a coefficient table (Table 8.1):
//              delta_r* = C1 delta_f + C2 delta_f^3,                (8.6)
//              delta_r*' = (C1 + 3 C2 delta_f^2) delta_f',          (8.7)
//              delta_r*'' = (C1 + 3 C2 delta_f^2) delta_f'' + 6 C2 delta_f delta_f'^2   (8.8)
//              (the scan's "5 C2" read as 6 C2, the derivative of (8.7));
//              beyond a row's fitted front angles (front_max_deg) its Kr is
//              continued by a bounded C2 saturation below 1 and the two rows'
//              laws interpolated in speed (KrTable in linear_ratio.h); (8.6)-(8.8)
//              become delta_r* = Kr delta_f, delta_r*' = S delta_f',
//              delta_r*'' = S delta_f'' + S' delta_f'^2 with S = d delta_r*/d delta_f
//              and S' its derivative (KrTable::calcRear).
// Kr is evaluated at the current speed and its time derivative through U is
// neglected (the seed's manoeuvres hold the speed constant).
#include <memory>
#include <string>
#include <vector>

#include <Simbody.h>

#include "vdyn/core/registry.h"
#include "vdyn/core/scene.h"
#include "vdyn/core/steering_actuator.h"
#include "vdyn/steering_ratio/linear_ratio.h"

namespace vdyn {

// LinearBicycleParams, the linear law (6.9) calcLinearOptimalRatio() and the
// coefficient table KrTable come from vdyn/steering_ratio/linear_ratio.h (one
// definition, shared with the steering-ratio analysis that writes the table).

/// The rear angle's target and its derivatives (rad, rad/s, rad/s^2) and the
/// ratio Kr(U, delta_f) = delta_r* / delta_f (its limit at delta_f = 0).
struct RearSteerTarget {
  double angle_rad = 0, rate_rad_s = 0, accel_rad_s2 = 0, kr = 0;
};

class RearSteerStrategy {
 public:
  virtual ~RearSteerStrategy() = default;
  /// "2ws", "linear" or "nonlinear".
  virtual std::string name() const = 0;
  /// Target at speed U (m/s) for the front angle delta_f (rad) and its rate
  /// and acceleration; throws Error if an input is not finite.
  RearSteerTarget calcTarget(double speed_m_s, double df_rad, double df_rate_rad_s, double df_accel_rad_s2) const;

 protected:
  virtual RearSteerTarget DoCalcTarget(double U, double df, double dfd, double dfdd) const = 0;
};

class TwoWsStrategy : public RearSteerStrategy {
 public:
  std::string name() const override { return "2ws"; }

 protected:
  RearSteerTarget DoCalcTarget(double, double, double, double) const override { return {}; }
};

class LinearKrStrategy : public RearSteerStrategy {
 public:
  explicit LinearKrStrategy(const LinearBicycleParams& p);
  std::string name() const override { return "linear"; }

 protected:
  RearSteerTarget DoCalcTarget(double U, double df, double dfd, double dfdd) const override;

 private:
  LinearBicycleParams p_;
};

class NonlinearKrStrategy : public RearSteerStrategy {
 public:
  explicit NonlinearKrStrategy(KrTable table);
  std::string name() const override { return "nonlinear"; }

 protected:
  RearSteerTarget DoCalcTarget(double U, double df, double dfd, double dfdd) const override;

 private:
  KrTable table_;
};

/// What a strategy's factory receives besides its parameters (family
/// "rear_steer_strategy" of the registry, registry.h ChoiceFactory).
struct RearSteerContext {
  LinearBicycleParams linear;       ///< the plugin's linear bicycle (defaults: chapter 6 values)
  const KrTable* table = nullptr;   ///< the plugin's Kr coefficient table, if it names one
};

/// The built-in strategies: 2ws, linear, nonlinear (in this order).
const std::vector<std::string>& rearSteerStrategyNames();
/// Registers 2ws, linear and nonlinear in family "rear_steer_strategy" (Base
/// RearSteerStrategy, context RearSteerContext); an out-of-tree library adds
/// its own with registry.addChoice<RearSteerStrategy, RearSteerContext>(...).
void registerRearSteerStrategies(PluginRegistry& registry);
/// The strategy registered as `name` (in `registry`, or the built-ins if
/// nullptr); `params` is the rear_steer plugin's entry (the strategy may read
/// keys of its own), or none. Throws Error naming `name` and the known ones
/// if unknown, or if "nonlinear" is asked without a table.
std::shared_ptr<const RearSteerStrategy> makeRearSteerStrategy(const std::string& name, const LinearBicycleParams& linear,
                                                               const KrTable* table,
                                                               const PluginRegistry* registry = nullptr,
                                                               const ParamReader* params = nullptr);

/// Tracking gains of (8.5)/(8.8).
struct RearSteerParams {
  double g1_per_s2 = 10;  ///< G1 on delta_r* - delta_r, 1/s^2
  double g2_per_s = 10;   ///< G2 on delta_r*' - delta_r', 1/s
  void validate() const;
  /// Keys g1_per_s2, g2_per_s.
  static RearSteerParams fromParams(const ParamReader& r);
};

struct RearSteerEvaluation {
  double speed_m_s = 0;
  double front_angle_rad = 0, front_rate_rad_s = 0, front_accel_rad_s2 = 0;
  RearSteerTarget target;
  double rear_angle_rad = 0, rear_rate_rad_s = 0;
  double accel_rad_s2 = 0;  ///< delta_r'' (8.5)/(8.8)
};

class RearSteerLaw : public SteeringLaw {
 public:
  /// `front` and `rear`: state-driven steerings of the same scene (the front
  /// one driven by a law of its own, e.g. a path controller).
  RearSteerLaw(std::string name, std::shared_ptr<const RearSteerStrategy> strategy, const RearSteerParams& params,
               const SteeringActuator& front, const SteeringActuator& rear, const SimTK::MobilizedBody& chassis);
  /// The evaluation on a state realized to Stage::Velocity, the front's
  /// delta'' from its steering (Stage::Dynamics where the vehicle's dense rows
  /// solve it). Without `withFrontAcceleration` that is taken as 0: the
  /// target's angle, rate and Kr do not depend on it; its acceleration and
  /// accel_rad_s2 are then NaN.
  RearSteerEvaluation calcEvaluation(const SimTK::State& s, bool withFrontAcceleration = true) const;
  const RearSteerStrategy& strategy() const { return *strategy_; }

 protected:
  double DoCalcAcceleration(const SimTK::State& s) const override { return calcEvaluation(s).accel_rad_s2; }

 private:
  std::shared_ptr<const RearSteerStrategy> strategy_;
  RearSteerParams p_;
  const SteeringActuator* front_;  // owned by the same scene
  const SteeringActuator* rear_;
  SimTK::MobilizedBody chassis_;
};

/// Controller plugin: sets a RearSteerLaw on the rear state-driven steering
/// plugin, reading the front one (which must be state-driven, e.g. by a path
/// controller). Outputs <name>.kr, <name>.target_rad and
/// <name>.tracking_error_rad (delta_r - delta_r*).
class RearSteerPlugin : public ControllerPlugin {
 public:
  RearSteerPlugin(std::string name, std::string rearSteering, std::string frontSteering, std::string chassisBody,
                  std::shared_ptr<const RearSteerStrategy> strategy, const RearSteerParams& params);
  const RearSteerLaw& law() const;
  /// Names of the rear steering plugin it drives and the front one it reads.
  const std::string& rearSteering() const { return rear_; }
  const std::string& frontSteering() const { return front_; }
  /// The strategy (shared: a path controller's 4WS feed-forward reads its Kr).
  const std::shared_ptr<const RearSteerStrategy>& strategyHandle() const { return strategy_; }

 protected:
  void DoAddTo(Scene& scene) override;

 private:
  std::string rear_, front_, chassis_;
  std::shared_ptr<const RearSteerStrategy> strategy_;
  RearSteerParams p_;
  std::shared_ptr<const RearSteerLaw> law_;
};

/// Registers "rear_steer" (and the strategies, registerRearSteerStrategies): {"rear_steering": "rear_steer", "front_steering":
/// "front_steer", "chassis": "chassis", "strategy": "linear", "g1_per_s2": 10,
/// "g2_per_s": 10, "linear_bicycle": {...} (optional, chapter 6 values by
/// default), "kr_table": "file.json" (nonlinear only)}.
void registerRearSteerPlugins(PluginRegistry& registry);

}  // namespace vdyn
