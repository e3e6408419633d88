#include "vdyn/vehicles/fourws.h"

#include <algorithm>

#include "vdyn/vehicles/chassis_outputs.h"

#include "vdyn/core/simulation.h"
#include "vdyn/plugins/builtin.h"
#include "vdyn/speed/speed_hold.h"

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
  makeRoad(road);
  requireNonNegative(gravity_m_per_s2, "4ws gravity_m_per_s2");
  if (tire.plugin.empty()) throw Error("4ws tire plugin name is empty");
  if (corner_model != "constrained" && corner_model != "reduced")
    throw Error("4ws corner_model must be \"constrained\" or \"reduced\", got \"" + corner_model + "\"");
  if (forward_dynamics != "simbody" && forward_dynamics != "dense")
    throw Error("4ws forward_dynamics must be \"simbody\" or \"dense\", got \"" + forward_dynamics + "\"");
  if (forward_dynamics == "dense" && corner_model != "reduced")
    throw Error("4ws forward_dynamics \"dense\" needs corner_model \"reduced\" (got \"" + corner_model + "\")");
}

const FieldTable<FourWsParams>& FourWsParams::fields() {
  using P = FourWsParams;
  static const auto t =
      FieldTable<P>()
          .custom("chassis", "-", "required", "rigid body: mass_kg, inertia_kg_m2, ... (appendix_a.json)",
                  [](const ParamReader& r, P& p) { p.chassis = RigidBodyParams::fromParams(r.child("chassis")); })
          .custom("front_right", "-", "required", "double-wishbone corner (LF mirrored from it)",
                  [](const ParamReader& r, P& p) {
                    p.front_right = DoubleWishboneParams::fromParams(r.child("front_right"));
                  })
          .custom("rear_right", "-", "required", "double-wishbone corner (LR mirrored from it)",
                  [](const ParamReader& r, P& p) {
                    p.rear_right = DoubleWishboneParams::fromParams(r.child("rear_right"));
                  })
          .custom("tire", "-", "required",
                  "{\"plugin\": gim|fiala|linear|..., \"params\": {the tire's 'params: ...' keys (vdyn list gim)}}",
                  [](const ParamReader& r, P& p) { p.tire = TireChoice::fromParams(r.child("tire")); })
          .custom("road", "-", "{\"type\": \"flat\"}", "road: {\"type\": flat|sine, ...}",
                  [](const ParamReader& r, P& p) {
                    if (r.has("road")) p.road = RoadParams::fromParams(r.child("road"));
                  })
          .number("gravity_m_per_s2", &P::gravity_m_per_s2, "m/s^2", "gravity along -z")
          .string("corner_model", &P::corner_model,
                  "constrained (each loop closed by a ball constraint) | reduced (loop solved in the knuckle's "
                  "mobilizer)")
          .string("forward_dynamics", &P::forward_dynamics,
                  "simbody | dense (reduced corners only: the constraint rows solved as one dense system)");
  return t;
}

FourWsParams FourWsParams::fromParams(const ParamReader& r) {
  FourWsParams p = fields().read(r);
  if (p.corner_model != "constrained" && p.corner_model != "reduced")
    throw Error(r.where() + ": corner_model must be \"constrained\" or \"reduced\", got \"" + p.corner_model + "\"");
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
  reduced_ = p_.corner_model == "reduced";
  if (reduced_) registry_ = std::make_shared<PluginRegistry>(registry);
  SimTK::Force::Gravity(sc.updForces(), sc.updMatter(), -SimTK::UnitVec3(SimTK::ZAxis), p_.gravity_m_per_s2);
  chassis_ = SimTK::MobilizedBody::Free(
      sc.updMatter().Ground(), SimTK::Transform(),
      makeRigidBody(p_.chassis),
      SimTK::Transform());
  sc.addBody("chassis", chassis_);
  cornerParams_ = {p_.front_right, p_.front_right.mirrored(), p_.rear_right, p_.rear_right.mirrored()};
  sc.setService<const Road>("road", makeRoad(p_.road));
  for (int c = 0; c < 4; ++c) {
    const std::string prefix = std::string(cornerName(c)) + ".";
    if (reduced_) {
      loops_[c] = std::make_unique<WishboneLoop>(cornerParams_[c]);
      reducedCorners_[c] = buildReducedWishbone(sc, chassis_, cornerParams_[c], *loops_[c], prefix);
    } else {
      corners_[c] = buildDoubleWishbone(sc, chassis_, cornerParams_[c], prefix);
    }
    const PluginSpec spec = p_.tire.makeSpec(std::string("tire_") + cornerName(c), prefix + "wheel",
                                             Json{{"side", c == RF || c == RR ? "right" : "left"}});
    tires_[c] = dynamic_cast<const TirePlugin*>(
        &sc.addPlugin(registry.create(PluginKind::ForceElement, p_.tire.plugin, spec, "4ws tire plugin")));
    if (!tires_[c]) throw Error("4ws tire plugin '" + p_.tire.plugin + "' is not a tire plugin");
    const SimTK::MobilizedBody wheel = sc.getBody(prefix + "wheel");
    sc.addOutput({prefix + "spin_rad_s", "rad/s", SimTK::Stage::Velocity,
                  [wheel](const SimTK::State& s) { return wheel.getOneU(s, 0); }});
  }

  if (reduced_) {  // every arm row in one constraint object
    std::vector<ArmPlanesImpl::Row> rows;
    for (int c = 0; c < 4; ++c) {
      const auto r = armPlaneRows(cornerParams_[c], reducedCorners_[c].lower_arm, reducedCorners_[c].knuckle,
                                  reducedCorners_[c].upper_arm);
      rows.insert(rows.end(), r.begin(), r.end());
    }
    SimTK::Constraint::Custom(new ArmPlanesImpl(sc.updMatter(), rows));
    dense_ = new ReducedDenseRows(sc.getMatter(), sc.getForces());
    SimTK::Force::Custom(sc.updForces(), dense_);  // inactive until useDenseRows()
  }
  addChassisOutputs(sc, chassis_);
}

const SteeringPlugin& FourWsVehicle::addAxleSteering(const std::string& name, bool front,
                                                     std::shared_ptr<const SteeringCommand> command) {
  const int r = front ? RF : RR, l = front ? LF : LR;
  axleSteering_.push_back({name, front, command, 0.0});
  auto plugin = std::make_unique<SteeringPlugin>(
      name, "chassis", std::vector<std::string>{std::string(cornerName(r)) + ".knuckle", std::string(cornerName(l)) + ".knuckle"},
      std::move(command), SimTK::UnitVec3(cornerParams_[r].wheel_spin_axis));
  return static_cast<const SteeringPlugin&>(scene_->addPlugin(std::move(plugin)));
}

SteeringPlugin& FourWsVehicle::addAxleSteering(const std::string& name, bool front, const SteeringStateSpec& state) {
  const int r = front ? RF : RR, l = front ? LF : LR;
  axleSteering_.push_back({name, front, nullptr, state.initial_angle_rad});
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
  const int denseRows = dense_ && dense_->isActive(s) ? dense_->numRows() : 0;  // rows Simbody does not see
  return s.getNU() - s.getNUDotErr() - denseRows - static_cast<int>(steeringStateBodies(*scene_).size());
}

SimTK::State FourWsVehicle::makeInitialState(double speed, AssemblyReport* report) const {
  requireFinite(speed, "4ws initial speed_m_s");
  const SimTK::MultibodySystem& system = scene_->getSystem();
  SimTK::State s = scene_->getDefaultState();
  const double road0 = makeRoad(p_.road)->height(0, 0, 0);
  const TireModel& tire = tires_[0]->getModel();
  const double deflection = calcStaticDeflection(tire, totalMass() * p_.gravity_m_per_s2 / 4);
  double wcz = 0;
  for (const auto& c : cornerParams_) wcz += wheelCentreInChassis(c)[2] / 4;
  chassis_.setQToFitTranslation(s, Vec3(0, 0, road0 + tire.vertical().unloaded_radius_m - deflection - wcz));
  system.realize(s, SimTK::Stage::Position);

  std::vector<std::pair<std::string, SimTK::MobilizedBody>> bodies;
  for (int c = 0; c < 4; ++c) {
    const std::string n = cornerName(c);
    for (const char* b : {".lower_arm", ".knuckle", ".upper_arm", ".wheel"})
      bodies.push_back({n + b, scene_->getBody(n + b)});
  }
  double gap = 0;  // the reduced loop is closed by construction
  AssemblyReport conReport;
  if (reduced_) {
    // The constrained model's assembly (same data, axle steering held at its
    // initial angles), read into the reduced coordinates.
    FourWsParams cp = p_;
    cp.corner_model = "constrained";
    cp.forward_dynamics = "simbody";
    FourWsVehicle con(cp, *registry_);
    for (const AxleSteering& a : axleSteering_)
      con.addAxleSteering(a.name, a.front,
                          std::make_shared<HoldCommand>(a.command ? a.command->calcAt(s.getTime()).angle_rad
                                                                  : a.initial_angle_rad));
    // Steering plugins a scene file added through the registry (not through
    // addAxleSteering) are held in the copy the same way, in scene order:
    // without them the copy's knuckles assembled unsteered and the reduced
    // vehicle started elsewhere than the same composition in C++.
    for (const auto& plugin : scene_->getPlugins()) {
      const auto* sp = dynamic_cast<const SteeringPlugin*>(plugin.get());
      if (!sp || std::any_of(axleSteering_.begin(), axleSteering_.end(),
                             [&](const AxleSteering& a) { return a.name == sp->name(); }))
        continue;
      const double angle = sp->isStateDriven() ? sp->getSteerBody().getDefaultAngle()
                                               : sp->command().calcAt(s.getTime()).angle_rad;
      con.updScene().addPlugin(std::make_unique<SteeringPlugin>(sp->name(), sp->chassisBody(), sp->knuckleBodies(),
                                                                std::make_shared<HoldCommand>(angle), sp->spinAxis()));
    }
    const SimTK::State cs = con.makeInitialState(0.0, &conReport);
    chassis_.setQ(s, con.chassis().getQ(cs));
    for (int c = 0; c < 4; ++c) {
      const SimTK::UnitVec3 spin(cornerParams_[c].wheel_spin_axis);
      setReducedCornerPosition(s, reducedCorners_[c], con.suspensionAngle(cs, c),
                               steeringAngle(cs, con.chassis(), con.corner(c).knuckle, spin));
    }
    gap = conReport.initial_loop_gap_m;
  }
  std::vector<SimTK::MobilizedBodyIndex> locked = {chassis_.getMobilizedBodyIndex()};
  for (int c = 0; c < 4; ++c) {
    locked.push_back(scene_->getBody(std::string(cornerName(c)) + ".wheel").getMobilizedBodyIndex());
    if (reduced_) continue;
    const auto& j = cornerParams_[c].upper_ball;
    gap = std::max(gap, (corners_[c].upper_arm.findStationLocationInGround(s, j.parent_point_m) -
                         corners_[c].knuckle.findStationLocationInGround(s, j.child_point_m)).norm());
  }
  for (auto mbx : steeringStateBodies(*scene_)) locked.push_back(mbx);  // keep delta at its initial value
  assembleLoops(system, s, locked, bodies, gap, "4ws", report);
  if (reduced_ && report) *report = conReport;  // the moves that made this configuration
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
  for (int c = 0; c < 4; ++c) scene_->getBody(std::string(cornerName(c)) + ".wheel").setOneU(s, 0, spin[c]);
  system.realize(s, SimTK::Stage::Velocity);
  for (const TirePlugin* t : tires_) t->getForceElement().initializeRelaxationStates(s);
  if (p_.forward_dynamics == "dense") {
    useDenseRows(s);
    system.realize(s, SimTK::Stage::Velocity);
  }
  return s;
}

const DoubleWishboneCorner& FourWsVehicle::corner(int c) const {
  if (reduced_) throw Error("4ws: corner() is the constrained model's; this vehicle is reduced (use reducedCorner())");
  return corners_.at(c);
}

const ReducedWishboneCorner& FourWsVehicle::reducedCorner(int c) const {
  if (!reduced_) throw Error("4ws: reducedCorner() on a constrained vehicle (corner_model \"constrained\")");
  return reducedCorners_.at(c);
}

double FourWsVehicle::suspensionAngle(const SimTK::State& s, int c) const {
  return scene_->getBody(std::string(cornerName(c)) + ".lower_arm").getOneQ(s, 0);
}

SimTK::State FourWsVehicle::makeStateLike(const FourWsVehicle& other, const SimTK::State& os) const {
  if (!reduced_) throw Error("4ws: makeStateLike() builds a reduced model's state; this vehicle is constrained");
  const SimTK::MultibodySystem& system = scene_->getSystem();
  const Scene& osc = other.getScene();
  osc.getSystem().realize(os, SimTK::Stage::Velocity);
  SimTK::State s = scene_->getDefaultState();
  s.setTime(os.getTime());
  chassis_.setQ(s, other.chassis().getQ(os));
  chassis_.setU(s, other.chassis().getU(os));
  for (int c = 0; c < 4; ++c) {
    const std::string n = cornerName(c);
    const SimTK::MobilizedBody& ok = osc.getBody(n + ".knuckle");
    const SimTK::UnitVec3 spin(cornerParams_[c].wheel_spin_axis);
    // (A.1) angle and its rate: x . f = -sin(delta), d/dt (x . f) = (w_K - w_C) . (f x x).
    const SimTK::Vec3 x = other.chassis().getBodyRotation(os).x();
    const SimTK::Vec3 f = ok.getBodyRotation(os) * spin.asVec3();
    const double delta = std::asin(-SimTK::dot(x, f));
    const double xfdot = SimTK::dot(ok.getBodyAngularVelocity(os) - other.chassis().getBodyAngularVelocity(os),
                                    SimTK::cross(f, x));
    const double sAng = other.suspensionAngle(os, c);
    setReducedCornerPosition(s, reducedCorners_[c], sAng, delta);
    const double sRate = osc.getBody(n + ".lower_arm").getOneU(os, 0);
    const double deltaRate = -xfdot / std::cos(delta);
    reducedCorners_[c].knuckle.setOneU(s, 0, sRate);
    reducedCorners_[c].knuckle.setOneU(s, 1, deltaRate);
    reducedCorners_[c].lower_arm.setOneU(s, 0, sRate);
    reducedCorners_[c].upper_arm.setOneU(s, 0, loops_[c]->calcUpperArmAngle(sAng)[1] * sRate);
    const SimTK::MobilizedBody& ow = osc.getBody(n + ".wheel");
    reducedCorners_[c].wheel.setOneQ(s, 0, ow.getOneQ(os, 0));
    reducedCorners_[c].wheel.setOneU(s, 0, ow.getOneU(os, 0));
  }
  // State-driven steer bodies (same plugins, same order) and z variables.
  const auto mine = steeringStateBodies(*scene_), theirs = steeringStateBodies(osc);
  if (mine.size() != theirs.size()) throw Error("4ws makeStateLike: the vehicles have different steering plugins");
  for (std::size_t i = 0; i < mine.size(); ++i) {
    scene_->getMatter().getMobilizedBody(mine[i]).setOneQ(s, 0, osc.getMatter().getMobilizedBody(theirs[i]).getOneQ(os, 0));
    scene_->getMatter().getMobilizedBody(mine[i]).setOneU(s, 0, osc.getMatter().getMobilizedBody(theirs[i]).getOneU(os, 0));
  }
  if (s.getNZ() != os.getNZ()) throw Error("4ws makeStateLike: the vehicles have different z variables");
  s.updZ() = os.getZ();
  system.realize(s, SimTK::Stage::Position);
  system.project(s, 1e-12);
  if (p_.forward_dynamics == "dense") useDenseRows(s);
  system.realize(s, SimTK::Stage::Velocity);
  return s;
}

void FourWsVehicle::useDenseRows(SimTK::State& s) const {
  if (!reduced_) throw Error("4ws: dense forward dynamics needs corner_model \"reduced\"");
  const Scene& sc = *scene_;
  std::vector<ReducedDenseRows::Arm> arms;
  for (int c = 0; c < 4; ++c)
    arms.push_back({reducedCorners_[c].lower_arm, reducedCorners_[c].upper_arm, reducedCorners_[c].knuckle,
                    loops_[c].get()});
  std::vector<ReducedDenseRows::Steer> steers;
  std::vector<ReducedDenseRows::Speed> speeds;
  const std::string why = " (forward_dynamics \"dense\" solves only time-commanded steering of the knuckles and "
                          "speed holds on the chassis; use forward_dynamics \"simbody\")";
  for (const auto& plugin : sc.getPlugins()) {
    if (const auto* st = dynamic_cast<const SteeringPlugin*>(plugin.get())) {
      if (st->isStateDriven()) throw Error("4ws: steering plugin '" + plugin->name() + "' is state-driven" + why);
      if (sc.getBody(st->chassisBody()).getMobilizedBodyIndex() != chassis_.getMobilizedBodyIndex())
        throw Error("4ws: steering plugin '" + plugin->name() + "' is not on the chassis" + why);
      for (const std::string& k : st->knuckleBodies()) {
        int c = 0;
        while (c < 4 && std::string(cornerName(c)) + ".knuckle" != k) ++c;
        if (c == 4) throw Error("4ws: steering plugin '" + plugin->name() + "' steers '" + k + "', not a knuckle" + why);
        if ((st->spinAxis().asVec3() - SimTK::UnitVec3(cornerParams_[c].wheel_spin_axis).asVec3()).norm() > 1e-12)
          throw Error("4ws: steering plugin '" + plugin->name() + "' measures (A.1) about another spin axis than " + k +
                      "'s" + why);
        steers.push_back({reducedCorners_[c].knuckle, st->sharedCommand()});
      }
    } else if (const auto* sp = dynamic_cast<const SpeedHoldPlugin*>(plugin.get())) {
      if (sc.getBody(sp->chassisBody()).getMobilizedBodyIndex() != chassis_.getMobilizedBodyIndex())
        throw Error("4ws: speed hold '" + plugin->name() + "' is not on the chassis" + why);
      const ReducedDenseRows* dense = dense_;
      const int k = int(speeds.size());
      sp->setDisabledForceSource([dense, k](const SimTK::State& st) { return dense->speedHoldForce(st, k); });
      speeds.push_back({chassis_, sp});
    }
  }
  dense_->setRows(std::move(arms), std::move(steers), std::move(speeds));
  const SimTK::MultibodySystem& system = sc.getSystem();
  if (dense_->isActive(s)) return;
  system.realize(s, SimTK::Stage::Instance);
  if (s.getNUDotErr() != dense_->numRows())
    throw Error("4ws: the scene has " + std::to_string(s.getNUDotErr()) + " constraint rows, the dense path solves " +
                std::to_string(dense_->numRows()) + why);
  const SimTK::SimbodyMatterSubsystem& m = sc.getMatter();
  for (SimTK::ConstraintIndex cx(0); cx < m.getNumConstraints(); ++cx) m.getConstraint(cx).disable(s);
  dense_->setActive(s, true);
}

}  // namespace vdyn
