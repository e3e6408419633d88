#pragma once
// Constant vehicle speed, the seed's (3.18): K = v_xi^2 + v_eta^2 - U0^2 = 0,
// with v_xi, v_eta the velocity of the chassis origin along the chassis xi and
// eta axes. One nonholonomic constraint, scaled by 1 / (2 U0) so its error is in
// m/s. Its force acts at the chassis origin along (v_xi e_xi + v_eta e_eta) / U0
// (the constraint's gradient), and its multiplier is the force it takes to hold
// the speed: output <name>.force_N (> 0 propulsive, N).
#include <functional>
#include <memory>
#include <string>

#include <Simbody.h>

#include "vdyn/core/registry.h"
#include "vdyn/core/scene.h"

namespace vdyn {

class SpeedHoldImpl : public SimTK::Constraint::Custom::Implementation {
 public:
  SpeedHoldImpl(SimTK::SimbodyMatterSubsystem& matter, const SimTK::MobilizedBody& chassis, double speed_m_s);
  Implementation* clone() const override { return new SpeedHoldImpl(*this); }

  void calcVelocityErrors(const SimTK::State& s, const SimTK::Array_<SimTK::SpatialVec, SimTK::ConstrainedBodyIndex>& V_AB,
                          const SimTK::Array_<SimTK::Real, SimTK::ConstrainedUIndex>&,
                          SimTK::Array_<SimTK::Real>& verr) const override;
  void calcVelocityDotErrors(const SimTK::State& s, const SimTK::Array_<SimTK::SpatialVec, SimTK::ConstrainedBodyIndex>& A_AB,
                             const SimTK::Array_<SimTK::Real, SimTK::ConstrainedUIndex>&,
                             SimTK::Array_<SimTK::Real>& vaerr) const override;
  void addInVelocityConstraintForces(const SimTK::State& s, const SimTK::Array_<SimTK::Real>& multipliers,
                                     SimTK::Array_<SimTK::SpatialVec, SimTK::ConstrainedBodyIndex>& bodyForcesInA,
                                     SimTK::Array_<SimTK::Real, SimTK::ConstrainedUIndex>& mobilityForces) const override;
  /// Allocates the held speed as an Instance-stage state variable (default U0).
  void realizeTopology(SimTK::State& s) const override;

  /// The speed U0 held in this state, m/s.
  double getSpeed(const SimTK::State& s) const;
  /// Changes U0 in this state (> 0, m/s); invalidates Stage::Instance and above.
  void setSpeed(SimTK::State& s, double speed_m_s) const;

 private:
  /// Unit-free direction (v_xi e_xi + v_eta e_eta) / U0 in A for a chassis velocity.
  SimTK::Vec3 direction(const SimTK::Rotation& R_AB, const SimTK::Vec3& v_AB, double U0) const;
  SimTK::ConstrainedBodyIndex G_, B_;
  double U0_;  // default
  const SimTK::SimbodyMatterSubsystem* matter_;
  mutable SimTK::DiscreteVariableIndex speedIndex_;
};

class SpeedHoldPlugin : public ConstraintPlugin {
 public:
  /// speed_m_s > 0: the forward speed U0 held on the named chassis body.
  SpeedHoldPlugin(std::string name, std::string chassisBody, double speed_m_s);
  /// The default speed (the one a new state holds), m/s.
  double speed() const { return U0_; }
  /// Name of the chassis body whose speed is held.
  const std::string& chassisBody() const { return chassis_; }
  /// The speed held in `s`, and a way to change it without rebuilding the scene
  /// (continuation in speed); valid once the plugin is in a scene.
  double getSpeed(const SimTK::State& s) const;
  void setSpeed(SimTK::State& s, double speed_m_s) const;
  /// Releases (false) or re-engages (true) the hold in `s` (the vehicle then
  /// coasts); invalidates Stage::Instance and above.
  void setEnabled(SimTK::State& s, bool enabled) const;
  /// Force the constraint applies along the direction of travel, N (needs
  /// Stage::Acceleration).
  double calcForce(const SimTK::State& s) const;
  /// For a model that solves this row itself with the constraint disabled in
  /// its states (WheeledVehicle::useDenseRows): in a state where `active` is
  /// true, calcForce reads the force from `force` (N, same sign; 0 when
  /// released) and setEnabled releases or engages the row by `setEnabled`.
  struct ExternalRow {
    std::function<bool(const SimTK::State&)> active;
    std::function<double(const SimTK::State&)> force;
    std::function<void(SimTK::State&, bool)> setEnabled;
  };
  void setExternalRow(ExternalRow row) const { external_ = std::move(row); }

 protected:
  void DoAddTo(Scene& scene) override;
  /// The vehicle's initial speed must be the held speed (else the first
  /// velocity projection fails): a named Error instead.
  void DoCheckInitialState(const Scene& scene, const SimTK::State& initial) const override;
  /// "speed_m_s" (setSpeed).
  std::vector<std::string> DoGetAdjustables() const override { return {"speed_m_s"}; }
  void DoSetAdjustable(SimTK::State& state, const std::string&, double value) const override { setSpeed(state, value); }

 private:
  std::string chassis_;
  double U0_;
  SimTK::Constraint::Custom constraint_;
  const SpeedHoldImpl* impl_ = nullptr;
  mutable ExternalRow external_;  ///< set by the vehicle that solves the row (not a work buffer)
};

/// Registers "speed_hold": {"chassis": "chassis", "speed_m_s": 10}.
void registerSpeedPlugins(PluginRegistry& registry);

}  // namespace vdyn
