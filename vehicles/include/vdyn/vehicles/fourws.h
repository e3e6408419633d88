#pragma once
// The seed's Appendix A four-wheel-steering vehicle (docs/vehicle_data.md): the
// chassis on a free (6-dof) mobilizer, four double-wishbone corners (the left
// ones mirrored from the right in the builder), four wheels on spin joints, the
// suspension spring-dampers and four tire plugins on the scene's road. Steering
// constraints are plugins added on top (without them each knuckle turns freely
// about its kingpin: 18 degrees of freedom; with four, 14).
#include <array>
#include <memory>
#include <string>

#include "vdyn/core/registry.h"
#include "vdyn/core/scene.h"
#include "vdyn/steering/steering.h"
#include "vdyn/tire/road.h"
#include "vdyn/tire/tire_force.h"
#include "vdyn/vehicles/double_wishbone.h"
#include "vdyn/vehicles/quarter_car.h"
#include "vdyn/vehicles/reduced_dense.h"
#include "vdyn/vehicles/reduced_wishbone.h"

namespace vdyn {

/// Corner order of the seed's wheel numbering: 14 RF, 15 LF, 16 RR, 17 LR.
enum Corner { RF = 0, LF = 1, RR = 2, LR = 3 };
/// "rf", "lf", "rr", "lr": the body-name prefix of each corner.
const char* cornerName(int corner);

struct FourWsParams {
  RigidBodyParams chassis;               ///< body 1 (800 kg; 250/1000/1100 kg m^2)
  DoubleWishboneParams front_right;      ///< bodies 2, 3, 4, 14; LF is its mirror
  DoubleWishboneParams rear_right;       ///< bodies 8, 9, 10, 16; LR is its mirror
  TireChoice tire;                       ///< one tire kind and params for the four wheels
  RoadParams road;                       ///< flat by default
  double gravity_m_per_s2 = 9.81;        ///< along -z, m/s^2
  /// Data-file key "corner_model": "constrained" (default; each loop closed by
  /// a Constraint::Ball, the reference model) or "reduced" (the loop solved in
  /// the knuckle's mobilizer, q = [s, delta]; see reduced_wishbone.h). Both
  /// describe the same mechanism with the same bodies.
  std::string corner_model = "constrained";
  /// Data-file key "forward_dynamics" (reduced model only): "simbody"
  /// (default; the constraint rows solved by Simbody, projected each step) or
  /// "dense" (the same rows solved as one dense system per evaluation, with
  /// Baumgarte drift control; time-commanded steering only; see
  /// reduced_dense.h). makeInitialState and makeStateLike return dense states.
  std::string forward_dynamics = "simbody";

  void validate() const;
  /// Reads a vehicle data file in the layout of appendix_a.json.
  /// The data-file keys fromParams reads (`vdyn list vehicle`): the one key list.
  static const FieldTable<FourWsParams>& fields();
  static FourWsParams fromParams(const ParamReader& r);
  static FourWsParams fromFile(const std::string& path);
};

class FourWsVehicle {
 public:
  explicit FourWsVehicle(const FourWsParams& params);
  FourWsVehicle(const FourWsParams& params, const PluginRegistry& registry);

  Scene& updScene() { return *scene_; }
  const Scene& getScene() const { return *scene_; }
  const FourWsParams& params() const { return p_; }

  /// The tabulated configuration (chassis c.m. at the height where the tires
  /// carry about the weight, level, at the origin heading +x), the four loops
  /// closed by assembly, moving forward at `speed_m_s` with the wheels rolling.
  /// The reduced model starts in the constrained model's assembled
  /// configuration (a constrained copy of the vehicle, with the axle steering
  /// held at its initial angles, is assembled and its positions read), so
  /// both models start from the same state.
  SimTK::State makeInitialState(double speed_m_s = 0.0, AssemblyReport* report = nullptr) const;

  /// Adds a steering plugin that commands both wheels of the front (or rear)
  /// axle with the same angle; call before making states.
  const SteeringPlugin& addAxleSteering(const std::string& name, bool front,
                                        std::shared_ptr<const SteeringCommand> command);
  /// The same, state-driven: a controller plugin sets delta'' (see SteeringPlugin).
  SteeringPlugin& addAxleSteering(const std::string& name, bool front, const SteeringStateSpec& state);

  double totalMass() const;
  /// Mobilities minus constraint equations (the chassis quaternion counts as 3).
  int degreesOfFreedom(const SimTK::State& s) const;

  const SimTK::MobilizedBody::Free& chassis() const { return chassis_; }
  /// Constrained model only (throws Error on the reduced one).
  const DoubleWishboneCorner& corner(int c) const;
  bool isReduced() const { return reduced_; }
  /// Reduced model only (throws Error on the constrained one).
  const ReducedWishboneCorner& reducedCorner(int c) const;
  /// Suspension coordinate of a corner: the lower arm's pivot angle, rad (both models).
  double suspensionAngle(const SimTK::State& s, int c) const;
  /// Reduced model only: a state of this vehicle in the configuration and
  /// motion of `other` (a vehicle of the same data, either model) in state
  /// `os`: chassis, lower-arm angles, steering angles of (A.1), wheel spins,
  /// their rates, time and z variables (same plugins in the same order).
  /// The arm angles follow from s; the state is projected to the constraints.
  SimTK::State makeStateLike(const FourWsVehicle& other, const SimTK::State& os) const;
  /// Reduced model only: switches `s` to dense forward dynamics (see
  /// reduced_dense.h): every constraint row of the scene (arm rows, the
  /// steering plugins' time-commanded rows, speed holds) is disabled in `s`
  /// and solved by ReducedDenseRows instead. Throws Error (naming it) for a
  /// row it cannot solve (a state-driven steering plugin, any other
  /// constraint). Call after every plugin has been added.
  void useDenseRows(SimTK::State& s) const;
  /// The dense rows' force element (reduced model; null on the constrained one).
  const ReducedDenseRows* denseRows() const { return dense_; }
  const TirePlugin& tire(int c) const { return *tires_.at(c); }
  const DoubleWishboneParams& cornerParams(int c) const { return cornerParams_.at(c); }

 private:
  FourWsParams p_;
  std::unique_ptr<Scene> scene_;
  SimTK::MobilizedBody::Free chassis_;
  std::array<DoubleWishboneParams, 4> cornerParams_;
  std::array<DoubleWishboneCorner, 4> corners_;
  bool reduced_ = false;
  std::array<std::unique_ptr<WishboneLoop>, 4> loops_;
  std::array<ReducedWishboneCorner, 4> reducedCorners_;
  ReducedDenseRows* dense_ = nullptr;  ///< owned by its Force::Custom
  std::shared_ptr<const PluginRegistry> registry_;  ///< reduced: for the constrained copy
  struct AxleSteering {
    std::string name;
    bool front;
    std::shared_ptr<const SteeringCommand> command;  ///< null: state-driven
    double initial_angle_rad;
  };
  std::vector<AxleSteering> axleSteering_;
  std::array<const TirePlugin*, 4> tires_{};
};

}  // namespace vdyn
