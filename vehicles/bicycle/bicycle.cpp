#include "vdyn/vehicles/bicycle.h"

#include "vdyn/core/threads.h"

#include "vdyn/plugins/builtin.h"
#include "vdyn/vehicles/chassis_outputs.h"

namespace vdyn {

using SimTK::Vec3;

void BicycleParams::validate() const {
  chassis.validate("bicycle chassis");
  front_axle.validate("bicycle front_axle");
  rear_axle.validate("bicycle rear_axle");
  fork.validate("bicycle fork");
  requirePositive(front_track_m, "bicycle front_track_m");
  requirePositive(rear_track_m, "bicycle rear_track_m");
  if (!(front_axle_m[0] > rear_axle_m[0]))
    throw Error("bicycle front axle must lie ahead of the rear axle, got x = " + formatValue(front_axle_m[0]) +
                " and " + formatValue(rear_axle_m[0]));
  makeRoad(road);
  requireNonNegative(gravity_m_per_s2, "bicycle gravity_m_per_s2");
}

namespace {
/// Both corners of an axle lumped into one rigid axle body: mass summed, the
/// corners' principal inertias summed, plus m (track/2)^2 about x and z for the
/// two corner masses off the centre line.
RigidBodyParams lumpAxle(const DoubleWishboneParams& c, double track) {
  RigidBodyParams b;
  const double m = c.lower_arm.mass_kg + c.knuckle.mass_kg + c.upper_arm.mass_kg + c.wheel.mass_kg;
  const Vec3 I = c.lower_arm.inertia_kg_m2 + c.knuckle.inertia_kg_m2 + c.upper_arm.inertia_kg_m2 + c.wheel.inertia_kg_m2;
  const double off = m * track * track / 4;
  b.mass_kg = 2 * m;
  b.inertia_kg_m2 = Vec3(2 * I[0] + 2 * off, 2 * I[1], 2 * I[2] + 2 * off);
  return b;
}
}  // namespace

const FieldTable<BicycleParams>& BicycleParams::fields() {
  using P = BicycleParams;
  static const auto t =
      FieldTable<P>()
          .custom("vehicle_data", "-", "required",
                  "wheeled vehicle data file the axles are lumped from (its chassis, tire and the right corners of "
                  "its double-wishbone axles front and rear)",
                  [](const ParamReader& r, P& p) {
                    const ParamReader v = ParamReader::fromFile(r.string("vehicle_data"));
                    p.chassis = RigidBodyParams::fromParams(v.child("chassis"));
                    const ParamReader axles = v.child("axles");
                    auto corner = [&](const char* axle) {
                      const ParamReader s = axles.child(axle).child("suspension");
                      s.has("template");  // either double-wishbone formulation: the same mechanism
                      return DoubleWishboneParams::fromParams(s);
                    };
                    const DoubleWishboneParams front = corner("front"), rear = corner("rear");
                    const Vec3 wf = wheelCentreInChassis(front), wr = wheelCentreInChassis(rear);
                    p.front_axle_m = Vec3(wf[0], 0, wf[2]);
                    p.rear_axle_m = Vec3(wr[0], 0, wr[2]);
                    p.front_track_m = -2 * wf[1];
                    p.rear_track_m = -2 * wr[1];
                    p.front_axle = lumpAxle(front, p.front_track_m);
                    p.rear_axle = lumpAxle(rear, p.rear_track_m);
                    // The vehicle data's tire, with this file's "tire" over it.
                    if (r.has("tire")) {
                      const ParamReader t = r.child("tire");
                      p.tire = TireChoice::fromParams(v.child("tire"), &t);
                    } else {
                      p.tire = TireChoice::fromParams(v.child("tire"));
                    }
                    v.child("chassis").requireAllKeysRead();
                    for (const char* k : {"front", "rear"}) axles.child(k).child("suspension").requireAllKeysRead();
                  })
          .sample("\"appendix_a.json\"")
          .custom("fork", "-", "required", "rigid body of the steered fork",
                  [](const ParamReader& r, P& p) { p.fork = RigidBodyParams::fromParams(r.child("fork")); })
          .custom("tire", "-", "the vehicle's",
                  "{\"plugin\", \"params\"} merged over the vehicle data's tire (read with vehicle_data)",
                  [](const ParamReader& r, P&) { r.has("tire"); })
          .sample("{}")
          .custom("road", "-", "{\"type\": \"flat\"}", "road: {\"type\": flat|sine, ...}",
                  [](const ParamReader& r, P& p) {
                    if (r.has("road")) p.road = RoadParams::fromParams(r.child("road"));
                  })
          .number("gravity_m_per_s2", &P::gravity_m_per_s2, "m/s^2", "gravity along -z");
  return t;
}

BicycleParams BicycleParams::fromParams(const ParamReader& r) {
  BicycleParams p = fields().read(r);
  p.validate();
  return p;
}

BicycleParams BicycleParams::fromFile(const std::string& path) { return fromParams(ParamReader::fromFile(path)); }

Bicycle::Bicycle(const BicycleParams& params) : Bicycle(params, builtinPlugins()) {}

Bicycle::Bicycle(const BicycleParams& params, const PluginRegistry& registry)
    : p_(params), scene_(std::make_unique<Scene>()) {
  p_.validate();
  Scene& sc = *scene_;
  SimTK::Force::Gravity(sc.updForces(), sc.updMatter(), -SimTK::UnitVec3(SimTK::ZAxis), p_.gravity_m_per_s2);
  chassis_ = SimTK::MobilizedBody::Free(sc.updMatter().Ground(), SimTK::Transform(), makeRigidBody(p_.chassis), SimTK::Transform());
  // Simbody's Pin turns about z: the steer axis is the chassis zeta axis; the
  // spin axes are eta (a frame rotated so that its z is eta).
  const SimTK::Rotation R_spin(SimTK::UnitVec3(SimTK::YAxis), SimTK::ZAxis);
  fork_ = SimTK::MobilizedBody::Pin(chassis_, SimTK::Transform(p_.front_axle_m), makeRigidBody(p_.fork), SimTK::Transform());
  front_ = SimTK::MobilizedBody::Pin(fork_, SimTK::Transform(R_spin), makeRigidBody(p_.front_axle), SimTK::Transform(R_spin));
  rear_ = SimTK::MobilizedBody::Pin(chassis_, SimTK::Transform(R_spin, p_.rear_axle_m), makeRigidBody(p_.rear_axle),
                                    SimTK::Transform(R_spin));
  sc.addBody("chassis", chassis_);
  sc.addBody("fork", fork_);
  sc.addBody("front_axle", front_);
  sc.addBody("rear_axle", rear_);
  sc.setService<const Road>("road", makeRoad(p_.road));
  struct Spec { const char* name; const char* body; double y; };
  const Spec specs[4] = {{"tire_fr", "front_axle", -p_.front_track_m / 2}, {"tire_fl", "front_axle", p_.front_track_m / 2},
                         {"tire_rr", "rear_axle", -p_.rear_track_m / 2}, {"tire_rl", "rear_axle", p_.rear_track_m / 2}};
  for (const Spec& t : specs) {
    // Both tires of an axle take the slip of the axle centre (see bicycle.h).
    const Json entry{{"centre_m", {0.0, t.y, 0.0}}, {"slip_centre_m", {0.0, 0.0, 0.0}}, {"side", t.y < 0 ? "right" : "left"}};
    const PluginSpec spec = p_.tire.makeSpec(t.name, t.body, entry);
    tires_.push_back(dynamic_cast<const TirePlugin*>(
        &sc.addPlugin(registry.create(PluginKind::ForceElement, p_.tire.plugin, spec, "bicycle tire plugin"))));
    if (!tires_.back()) throw Error("bicycle tire plugin '" + p_.tire.plugin + "' is not a tire plugin");
  }
  const auto f = front_, r = rear_;
  sc.addOutput({"front_axle.spin_rad_s", "rad/s", SimTK::Stage::Velocity, [f](const SimTK::State& s) { return f.getOneU(s, 0); }});
  sc.addOutput({"rear_axle.spin_rad_s", "rad/s", SimTK::Stage::Velocity, [r](const SimTK::State& s) { return r.getOneU(s, 0); }});
  addChassisOutputs(sc, chassis_);
}

const SteeringPlugin& Bicycle::addFrontSteering(const std::string& name, std::shared_ptr<const SteeringCommand> command) {
  auto plugin = std::make_unique<SteeringPlugin>(name, "chassis", std::vector<std::string>{"fork"}, std::move(command));
  return static_cast<const SteeringPlugin&>(scene_->addPlugin(std::move(plugin)));
}

SteeringPlugin& Bicycle::addFrontSteering(const std::string& name, const SteeringStateSpec& state) {
  auto plugin = std::make_unique<SteeringPlugin>(name, "chassis", std::vector<std::string>{"fork"}, state);
  return static_cast<SteeringPlugin&>(scene_->addPlugin(std::move(plugin)));
}

double Bicycle::totalMass() const {
  return p_.chassis.mass_kg + p_.fork.mass_kg + p_.front_axle.mass_kg + p_.rear_axle.mass_kg;
}

double Bicycle::distanceToFrontAxle() const {
  const double xc = ((p_.fork.mass_kg + p_.front_axle.mass_kg) * p_.front_axle_m[0] +
                     p_.rear_axle.mass_kg * p_.rear_axle_m[0]) / totalMass();
  return p_.front_axle_m[0] - xc;
}

double Bicycle::distanceToRearAxle() const {
  return (p_.front_axle_m[0] - p_.rear_axle_m[0]) - distanceToFrontAxle();
}

int Bicycle::degreesOfFreedom(const SimTK::State& s) const {
  scene_->getSystem().realize(s, SimTK::Stage::Instance);
  // A state-driven steering plugin's steer body moves by a prescribed acceleration.
  return s.getNU() - s.getNUDotErr() - static_cast<int>(steeringStateBodies(*scene_).size());
}

SimTK::State Bicycle::makeInitialState(double speed) const {
  requireFinite(speed, "bicycle initial speed_m_s");
  const SimTK::MultibodySystem& system = scene_->getSystem();
  SimTK::State s = scene_->getDefaultState();
  const TireModel& tire = tires_[0]->getModel();
  const double deflection = calcStaticDeflection(tire, totalMass() * p_.gravity_m_per_s2 / 4);
  const double road0 = makeRoad(p_.road)->height(0, 0, 0);
  const double zAxle = 0.5 * (p_.front_axle_m[2] + p_.rear_axle_m[2]);
  chassis_.setQToFitTranslation(s, Vec3(0, 0, road0 + tire.vertical().unloaded_radius_m - deflection - zAxle));
  system.realize(s, SimTK::Stage::Position);
  if (s.getQErr().size() > 0 && s.getQErr().normInf() > 1e-12) {
    SimTK::Assembler assembler(system);
    assembler.lockMobilizer(chassis_.getMobilizedBodyIndex());
    for (auto mbx : steeringStateBodies(*scene_)) assembler.lockMobilizer(mbx);  // keep delta at its initial value
    assembler.setErrorTolerance(1e-12);
    const auto lock = lockSimbodyAssembler();  // Simbody's Ipopt is not thread-safe (vdyn/core/threads.h)
    assembler.assemble(s);
  }
  s.updU() = 0;
  chassis_.setUToFitLinearVelocity(s, Vec3(speed, 0, 0));
  system.realize(s, SimTK::Stage::Velocity);
  // Free rolling at each axle's own heading speed and rolling radius.
  const ContactKinematics kf = tires_[0]->calcContact(s).kinematics, kr = tires_[2]->calcContact(s).kinematics;
  const TireModel& m = tires_[0]->getForceElement().getModel();
  const double wf = kf.vx_m_s / m.calcRollingRadius(kf.deflection_m), wr = kr.vx_m_s / m.calcRollingRadius(kr.deflection_m);
  front_.setOneU(s, 0, wf);
  rear_.setOneU(s, 0, wr);
  system.realize(s, SimTK::Stage::Velocity);
  for (const TirePlugin* t : tires_) t->getForceElement().initializeRelaxationStates(s);
  return s;
}

}  // namespace vdyn
