#include "vdyn/vehicles/fourws.h"

#include "vdyn/vehicles/chassis_outputs.h"

#include "vdyn/core/simulation.h"
#include "vdyn/plugins/builtin.h"

namespace vdyn {

using SimTK::Vec3;

const char* cornerName(int c) {
  static const char* names[4] = {"rf", "lf", "rr", "lr"};
  assert(c >= 0 && c < 4);
  return names[c];
}

void FourWsParams::validate() const {
  chassis.validate("4ws chassis");
  front_right.validate("4ws front_right");
  rear_right.validate("4ws rear_right");
  tire.validate("4ws tire");
  makeRoad(road);
  requireNonNegative(gravity_m_per_s2, "4ws gravity_m_per_s2");
  if (tire_plugin.empty()) throw Error("4ws tire plugin name is empty");
}

FourWsParams FourWsParams::fromParams(const ParamReader& r) {
  FourWsParams p;
  p.chassis = RigidBodyParams::fromParams(r.child("chassis"));
  p.front_right = DoubleWishboneParams::fromParams(r.child("front_right"));
  p.rear_right = DoubleWishboneParams::fromParams(r.child("rear_right"));
  const ParamReader tire = r.child("tire");
  p.tire_plugin = tire.string("plugin");
  p.tire = TireParams::fromParams(tire.child("params"));
  if (r.has("road")) p.road = RoadParams::fromParams(r.child("road"));
  p.gravity_m_per_s2 = r.numberOr("gravity_m_per_s2", p.gravity_m_per_s2);
  r.requireAllKeysRead();
  p.validate();
  return p;
}

FourWsParams FourWsParams::fromFile(const std::string& path) { return fromParams(ParamReader::fromFile(path)); }

FourWsVehicle::FourWsVehicle(const FourWsParams& params) : FourWsVehicle(params, builtinPlugins()) {}

FourWsVehicle::FourWsVehicle(const FourWsParams& params, const PluginRegistry& registry)
    : p_(params), scene_(std::make_unique<Scene>()) {
  p_.validate();
  Scene& sc = *scene_;
  SimTK::Force::Gravity(sc.updForces(), sc.updMatter(), -SimTK::UnitVec3(SimTK::ZAxis), p_.gravity_m_per_s2);
  chassis_ = SimTK::MobilizedBody::Free(
      sc.updMatter().Ground(), SimTK::Transform(),
      makeRigidBody(p_.chassis),
      SimTK::Transform());
  sc.addBody("chassis", chassis_);
  cornerParams_ = {p_.front_right, p_.front_right.mirrored(), p_.rear_right, p_.rear_right.mirrored()};
  sc.setService<const Road>("road", makeRoad(p_.road));
  const Json tireJson = p_.tire.toJson();
  for (int c = 0; c < 4; ++c) {
    const std::string prefix = std::string(cornerName(c)) + ".";
    corners_[c] = buildDoubleWishbone(sc, chassis_, cornerParams_[c], prefix);
    const PluginSpec spec{std::string("tire_") + cornerName(c),
                          ParamReader::fromJson(Json{{"params", tireJson}}, "4ws tire"),
                          {{"wheel", prefix + "wheel"}}};
    tires_[c] = dynamic_cast<const TirePlugin*>(
        &sc.addPlugin(registry.create(PluginKind::ForceElement, p_.tire_plugin, spec, "4ws tire plugin")));
    if (!tires_[c]) throw Error("4ws tire plugin '" + p_.tire_plugin + "' is not a tire plugin");
    const auto wheel = corners_[c].wheel;
    sc.addOutput({prefix + "spin_rad_s", "rad/s", SimTK::Stage::Velocity,
                  [wheel](const SimTK::State& s) { return wheel.getOneU(s, 0); }});
  }

  addChassisOutputs(sc, chassis_);
}

const SteeringPlugin& FourWsVehicle::addAxleSteering(const std::string& name, bool front,
                                                     std::shared_ptr<const SteeringCommand> command) {
  const int r = front ? RF : RR, l = front ? LF : LR;
  auto plugin = std::make_unique<SteeringPlugin>(
      name, "chassis", std::vector<std::string>{std::string(cornerName(r)) + ".knuckle", std::string(cornerName(l)) + ".knuckle"},
      std::move(command), SimTK::UnitVec3(cornerParams_[r].wheel_spin_axis));
  return static_cast<const SteeringPlugin&>(scene_->addPlugin(std::move(plugin)));
}

SteeringPlugin& FourWsVehicle::addAxleSteering(const std::string& name, bool front, const SteeringStateSpec& state) {
  const int r = front ? RF : RR, l = front ? LF : LR;
  auto plugin = std::make_unique<SteeringPlugin>(
      name, "chassis", std::vector<std::string>{std::string(cornerName(r)) + ".knuckle", std::string(cornerName(l)) + ".knuckle"},
      state, SimTK::UnitVec3(cornerParams_[r].wheel_spin_axis));
  return static_cast<SteeringPlugin&>(scene_->addPlugin(std::move(plugin)));
}

double FourWsVehicle::totalMass() const {
  double m = p_.chassis.mass_kg;
  for (const auto& c : cornerParams_) m += c.lower_arm.mass_kg + c.knuckle.mass_kg + c.upper_arm.mass_kg + c.wheel.mass_kg;
  return m;
}

int FourWsVehicle::degreesOfFreedom(const SimTK::State& s) const {
  scene_->getSystem().realize(s, SimTK::Stage::Instance);
  // A state-driven steering plugin's steer body moves by a prescribed acceleration.
  return s.getNU() - s.getNUDotErr() - static_cast<int>(steeringStateBodies(*scene_).size());
}

SimTK::State FourWsVehicle::makeInitialState(double speed, AssemblyReport* report) const {
  requireFinite(speed, "4ws initial speed_m_s");
  const SimTK::MultibodySystem& system = scene_->getSystem();
  SimTK::State s = scene_->getDefaultState();
  const double road0 = makeRoad(p_.road)->height(0, 0, 0);
  const double deflection = totalMass() * p_.gravity_m_per_s2 / 4 / p_.tire.radial_stiffness_N_per_m;
  double wcz = 0;
  for (const auto& c : cornerParams_) wcz += wheelCentreInChassis(c)[2] / 4;
  chassis_.setQToFitTranslation(s, Vec3(0, 0, road0 + p_.tire.unloaded_radius_m - deflection - wcz));
  system.realize(s, SimTK::Stage::Position);

  std::vector<std::pair<std::string, SimTK::MobilizedBody>> bodies;
  for (int c = 0; c < 4; ++c) {
    const std::string n = cornerName(c);
    bodies.push_back({n + ".lower_arm", corners_[c].lower_arm});
    bodies.push_back({n + ".knuckle", corners_[c].knuckle});
    bodies.push_back({n + ".upper_arm", corners_[c].upper_arm});
    bodies.push_back({n + ".wheel", corners_[c].wheel});
  }
  double gap = 0;
  for (int c = 0; c < 4; ++c) {
    const auto& j = cornerParams_[c].upper_ball;
    gap = std::max(gap, (corners_[c].upper_arm.findStationLocationInGround(s, j.parent_point_m) -
                         corners_[c].knuckle.findStationLocationInGround(s, j.child_point_m)).norm());
  }
  std::vector<SimTK::MobilizedBodyIndex> locked = {chassis_.getMobilizedBodyIndex()};
  for (const auto& c : corners_) locked.push_back(c.wheel.getMobilizedBodyIndex());
  for (auto mbx : steeringStateBodies(*scene_)) locked.push_back(mbx);  // keep delta at its initial value
  assembleLoops(system, s, locked, bodies, gap, "4ws", report);
  // Moving forward with every body at the chassis velocity and the wheels rolling.
  s.updU() = 0;
  chassis_.setUToFitLinearVelocity(s, Vec3(speed, 0, 0));
  system.realize(s, SimTK::Stage::Velocity);
  // Free rolling: each wheel spins at its own heading speed over its rolling radius
  // (assembly leaves a small toe on the knuckles, so headings differ slightly).
  std::array<double, 4> spin{};
  for (int c = 0; c < 4; ++c) {
    const ContactKinematics k = tires_[c]->calcContact(s).kinematics;
    spin[c] = k.vx_m_s / tires_[c]->getForceElement().getModel().calcRollingRadius(k.deflection_m);
  }
  for (int c = 0; c < 4; ++c) corners_[c].wheel.setOneU(s, 0, spin[c]);
  system.realize(s, SimTK::Stage::Velocity);
  for (const TirePlugin* t : tires_) t->getForceElement().initializeRelaxationStates(s);
  return s;
}

}  // namespace vdyn
