#include "vdyn/vehicles/wheeled_vehicle.h"

#include <algorithm>
#include <set>

#include "vdyn/vehicles/chassis_outputs.h"

#include "vdyn/core/simulation.h"
#include "vdyn/plugins/builtin.h"
#include "vdyn/speed/speed_hold.h"

namespace vdyn {

using SimTK::Vec3;

std::string SuspensionChoice::templateName() const { return block.value("template", std::string()); }

std::unique_ptr<Suspension> SuspensionChoice::create(const PluginRegistry& registry) const {
  return makeSuspension(registry, ParamReader::fromJson(block, where));
}

void WheeledVehicleParams::validate() const {
  chassis.validate("vehicle chassis");
  if (axles.empty()) throw Error("vehicle axles: a wheeled vehicle needs at least one axle");
  std::set<std::string> names;
  for (const AxleParams& a : axles) {
    if (a.tire.plugin.empty()) throw Error("vehicle axles." + a.name + ".tire: empty tire plugin name");
    for (const std::string& n : a.prefixes)
      if (n.empty() || !names.insert(n).second)
        throw Error("vehicle axles." + a.name + ".prefixes: corner name '" + n + "' is empty or taken by another axle");
  }
  makeRoad(road);
  requireNonNegative(gravity_m_per_s2, "vehicle gravity_m_per_s2");
  if (formulation != "auto" && formulation != "constrained" && formulation != "reduced" && formulation != "dense")
    throw Error("vehicle formulation must be \"auto\", \"constrained\", \"reduced\" or \"dense\", got \"" + formulation +
                "\"");
}

const AxleParams& WheeledVehicleParams::axle(const std::string& name) const {
  return const_cast<WheeledVehicleParams*>(this)->updAxle(name);
}

AxleParams& WheeledVehicleParams::updAxle(const std::string& name) {
  std::string known;
  for (AxleParams& a : axles) {
    if (a.name == name) return a;
    known += (known.empty() ? "" : ", ") + a.name;
  }
  throw Error("vehicle has no axle '" + name + "' (axles: " + known + ")");
}

void WheeledVehicleParams::setSuspensionTemplate(const std::string& name) {
  for (AxleParams& a : axles) a.suspension.block["template"] = name;
}

namespace {

/// Reads "axles": each axle's suspension (created once here, so a bad block
/// is an error at load), its tire over the vehicle's "tire", its corner
/// names; ordered front to rear by the right wheel centre's xi.
std::vector<AxleParams> readAxles(const ParamReader& r, const PluginRegistry& registry) {
  const ParamReader all = r.child("axles");
  if (!all.json().is_object() || all.json().empty())
    throw Error(all.where() + ": expected an object of axles by name, e.g. {\"front\": {...}, \"rear\": {...}}");
  std::vector<AxleParams> axles;
  for (const auto& [name, value] : all.json().items()) {
    const ParamReader a = all.child(name);
    AxleParams ax;
    ax.name = name;
    const ParamReader sb = a.child("suspension");
    ax.suspension.block = sb.json();
    ax.suspension.where = sb.where();
    const std::unique_ptr<Suspension> susp = makeSuspension(registry, sb);
    ax.wheel_centre_x_m = susp->calcWheelCentreInChassis(0)[0];  // order only: any common frame
    if (a.has("tire")) {
      const ParamReader own = a.child("tire");
      ax.tire = r.has("tire") ? TireChoice::fromParams(r.child("tire"), &own) : TireChoice::fromParams(own);
    } else {
      if (!r.has("tire"))
        throw Error(a.where() + ": tire: missing (give the axle a tire or the vehicle a \"tire\" for every axle)");
      ax.tire = TireChoice::fromParams(r.child("tire"));
    }
    if (a.has("prefixes")) {
      const Json& p = a.raw("prefixes");
      if (!p.is_array() || p.size() != 2 || !p[0].is_string() || !p[1].is_string())
        throw Error(a.where() + ".prefixes: expected [right, left] corner names, got " + p.dump());
      ax.prefixes = {p[0].get<std::string>(), p[1].get<std::string>()};
    } else {
      ax.prefixes = {std::string("r") + name[0], std::string("l") + name[0]};
    }
    if (a.has("anti_roll_bar")) {
      const ParamReader bar = a.child("anti_roll_bar");
      ax.anti_roll_bar = bar.json();
      ax.anti_roll_bar_where = bar.where();
      makeAntiRollBar(registry, bar);  // validates it at load
    }
    if (a.has("steering")) {
      const ParamReader st = a.child("steering");
      ax.steering = st.json();
      ax.steering_where = st.where();
      makeSteeringTemplate(registry, st);  // validates it at load
      if (!susp->usesRack())
        throw Error(st.where() + ": a rack needs the axle's suspension to have \"tie_rod\": \"rack\" (its "
                    "template '" + susp->templateName() + "' does not)");
    } else if (susp->usesRack()) {
      throw Error(sb.where() + ".tie_rod: \"rack\" needs the axle to have a \"steering\": {\"template\": "
                  "\"rack_and_pinion\", ...} block (" + a.where() + ".steering)");
    }
    a.requireAllKeysRead();
    axles.push_back(std::move(ax));
  }
  std::stable_sort(axles.begin(), axles.end(),
                   [](const AxleParams& x, const AxleParams& y) { return x.wheel_centre_x_m > y.wheel_centre_x_m; });
  if (r.has("tire")) r.child("tire").markAllRead();  // read by every axle that has no tire of its own
  return axles;
}

}  // namespace

const FieldTable<WheeledVehicleParams>& WheeledVehicleParams::fields() {
  using P = WheeledVehicleParams;
  static const auto t =
      FieldTable<P>()
          .custom("chassis", "-", "required",
                  "rigid body: mass_kg, inertia_kg_m2 [3] (principal, about the c.m.), com_m (the c.m. in the data's "
                  "chassis frame, default [0 0 0]: the chassis outputs refer to the c.m.)",
                  [](const ParamReader& r, P& p) {
                    const ParamReader c = r.child("chassis");
                    p.chassis = RigidBodyParams::fromParams(c);
                    p.chassis_com_m = c.vec3Or("com_m", SimTK::Vec3(0));
                  })
          .custom("tire", "-", "none",
                  "every axle's tire unless it has its own: {\"plugin\": gim|fiala|linear|magic_formula|..., "
                  "\"params\": {the kind's 'params: ...' keys (vdyn list gim)}}",
                  [](const ParamReader&, P&) {})  // read with the axles
          .custom("axles", "-", "required",
                  "{NAME: {\"suspension\": {\"template\": double_wishbone|double_wishbone_reduced|..., the "
                  "template's keys (right corner; \"left\" if not its mirror)}, \"tire\": {merged over the "
                  "vehicle's tire}, \"prefixes\": [right, left] (default r<N>, l<N>), \"anti_roll_bar\": "
                  "{\"template\": torsion_bar|..., the template's keys} (optional), \"steering\": {\"template\": "
                  "rack_and_pinion, its keys} (optional: a rack, the suspension's tie_rod \"rack\")}}, ordered front "
                  "to rear",
                  [](const ParamReader&, P&) {})  // read by fromParams, with the registry
          .custom("road", "-", "{\"type\": \"flat\"}", "road: {\"type\": flat|sine, ...}",
                  [](const ParamReader& r, P& p) {
                    if (r.has("road")) p.road = RoadParams::fromParams(r.child("road"));
                  })
          .number("gravity_m_per_s2", &P::gravity_m_per_s2, "m/s^2", "gravity along -z")
          .boolean("spring_free_length_from_ride_height", &P::spring_free_length_from_ride_height,
                   "true: every corner spring's free length is set so that the vehicle at rest sits at its "
                   "tabulated (design) configuration, each spring at its design length; the data's free lengths are "
                   "the start")
          .string("formulation", &P::formulation,
                  "auto | constrained | reduced | dense: the form of every axle's mechanism. constrained: the loops "
                  "closed by Simbody's constraint rows (the reference); reduced: the loops solved in the tree "
                  "(each template's reduced form); dense: reduced, with every constraint row solved as one dense "
                  "system; auto: dense when every axle's template has a reduced form and the scene's rows are all "
                  "dense ones, else reduced, else constrained (the run's summary says which and why). Default: "
                  "auto");
  return t;
}

WheeledVehicleParams WheeledVehicleParams::fromParams(const ParamReader& r, const PluginRegistry* registry) {
  WheeledVehicleParams p = fields().read(r);
  p.axles = readAxles(r, registry ? *registry : vehiclePlugins());
  r.requireAllKeysRead();
  p.validate();
  return p;
}

WheeledVehicleParams WheeledVehicleParams::fromFile(const std::string& path, const PluginRegistry* registry) {
  return fromParams(ParamReader::fromFile(path), registry);
}

WheeledVehicle::WheeledVehicle(const WheeledVehicleParams& params) : WheeledVehicle(params, vehiclePlugins()) {}

namespace {

void useSimbodyRowsOf(const Scene& scene, const ReducedDenseRows* dense, SimTK::State& s);

/// Sets every axle's template to the form `p.formulation` asks (auto: the
/// reduced form if every axle has one, else the constrained); returns the
/// form and why. Throws Error naming the axle when "reduced" or "dense" is
/// asked of a template without a reduced form.
WheeledVehicle::Formulation resolveTemplates(WheeledVehicleParams& p, const PluginRegistry& registry) {
  const std::string asked = "asked (formulation \"" + p.formulation + "\")";
  std::vector<std::string> reduced, constrained;
  std::string blocker;
  for (const AxleParams& a : p.axles) {
    const std::unique_ptr<Suspension> susp = a.suspension.create(registry);
    std::string whyNot;
    reduced.push_back(susp->getReducedTemplate(&whyNot));
    constrained.push_back(susp->getConstrainedTemplate());
    if (reduced.back().empty() && blocker.empty()) blocker = "axle '" + a.name + "''s template " + whyNot;
    if (reduced.back().empty() && (p.formulation == "reduced" || p.formulation == "dense"))
      throw Error("vehicle formulation \"" + p.formulation + "\": axle '" + a.name + "''s template " + whyNot +
                  " (formulation \"constrained\" or \"auto\" runs it)");
  }
  const bool useReduced = p.formulation != "constrained" && blocker.empty();
  for (std::size_t i = 0; i < p.axles.size(); ++i)
    p.axles[i].suspension.block["template"] = useReduced ? reduced[i] : constrained[i];
  if (useReduced) return {"reduced", p.formulation == "auto" ? "every axle's template has a reduced form" : asked};
  return {"constrained", p.formulation == "auto" ? blocker : asked};
}

}  // namespace

WheeledVehicle::WheeledVehicle(const WheeledVehicleParams& params, const PluginRegistry& registry)
    : p_(params.spring_free_length_from_ride_height ? params.withRideHeightSprings(registry) : params),
      scene_(std::make_unique<Scene>()) {
  p_.validate();
  templates_ = resolveTemplates(p_, registry);
  Scene& sc = *scene_;
  SimTK::Force::Gravity(sc.updForces(), sc.updMatter(), -SimTK::UnitVec3(SimTK::ZAxis), p_.gravity_m_per_s2);
  chassis_ = SimTK::MobilizedBody::Free(sc.updMatter().Ground(), SimTK::Transform(), makeRigidBody(p_.chassis),
                                        SimTK::Transform());
  sc.addBody("chassis", chassis_);
  sc.setService<const Road>("road", makeRoad(p_.road));
  for (std::size_t ai = 0; ai < p_.axles.size(); ++ai) {
    const AxleParams& ap = p_.axles[ai];
    axles_.push_back({ap.suspension.create(registry), nullptr, nullptr, 0.0});
    Suspension& susp = *axles_.back().suspension;
    if (p_.chassis_com_m != SimTK::Vec3(0)) susp.shiftChassisFrame(-p_.chassis_com_m);
    if (!ap.steering.empty()) {
      // The rack first: the corners' tie rods end on it.
      const ParamReader st = ParamReader::fromJson(ap.steering, ap.steering_where);
      Axle& axle = axles_.back();
      axle.rack = makeSteeringTemplate(registry, st);
      // N0 from the geometry (the data's frame: a rig on a fixed chassis).
      RackSteeringRig rig(ap.suspension.block, ap.suspension.where, axle.rack->params(), registry);
      axle.overall_ratio = rig.solve(0.0).overall_ratio;
      if (!std::isfinite(axle.overall_ratio))
        throw Error(ap.steering_where + ": the overall steering ratio at centre is not finite (the tie rods do not "
                    "steer the wheels)");
      if (p_.chassis_com_m != SimTK::Vec3(0)) axle.rack->shiftChassisFrame(-p_.chassis_com_m);
      const std::string body = ap.name + ".rack";
      susp.setRack(axle.rack->build(sc, chassis_, body));
      auto service = std::make_shared<SteeringRack>();
      service->body = body;
      service->travel_per_pinion_rad_m = axle.rack->params().travel_per_pinion_rad_m;
      service->overall_ratio = axle.overall_ratio;
      service->travel_limit_m = axle.rack->params().travel_limit_m;
      sc.setService<const SteeringRack>(body, service);
    }
    const std::string prefixes[2] = {ap.prefixes[0] + ".", ap.prefixes[1] + "."};
    susp.build(sc, chassis_, prefixes, [&](int side) {
      const std::string& n = ap.prefixes[side];
      Json entry{{"side", side == 0 ? "right" : "left"}};
      const SimTK::Vec3 spin = susp.getSpinAxis(side).asVec3();  // in the wheel frame (its axes the knuckle's at q = 0)
      if (spin != SimTK::Vec3(0, 1, 0)) entry["spin_axis"] = {spin[0], spin[1], spin[2]};
      const PluginSpec spec = ap.tire.makeSpec("tire_" + n, prefixes[side] + "wheel", entry);
      const auto* tire = dynamic_cast<const TirePlugin*>(
          &sc.addPlugin(registry.create(PluginKind::ForceElement, ap.tire.plugin, spec, ap.tire.where + ".plugin")));
      if (!tire) throw Error(ap.tire.where + ".plugin: '" + ap.tire.plugin + "' is not a tire plugin");
      tires_.push_back(tire);
      const SimTK::MobilizedBody wheel = sc.getBody(prefixes[side] + "wheel");
      sc.addOutput({prefixes[side] + "spin_rad_s", "rad/s", SimTK::Stage::Velocity,
                    [wheel](const SimTK::State& s) { return wheel.getOneU(s, 0); }});
    });
    if (!ap.anti_roll_bar.empty()) {
      const ParamReader bar = ParamReader::fromJson(ap.anti_roll_bar, ap.anti_roll_bar_where);
      axles_.back().anti_roll_bar = makeAntiRollBar(registry, bar);
      axles_.back().anti_roll_bar->build(sc, chassis_, susp, ap.name, bar.where());
    }
  }
  // Rows the templates gather into one constraint object for the whole vehicle.
  std::vector<ArmPlanesImpl::Row> rows;
  bool dense = true;
  for (const Axle& a : axles_) {
    for (int side = 0; side < 2; ++side) {
      const auto r = a.suspension->getArmRows(side);
      rows.insert(rows.end(), r.begin(), r.end());
    }
    dense = dense && a.suspension->supportsDenseRows();
  }
  if (!rows.empty()) SimTK::Constraint::Custom(new ArmPlanesImpl(sc.updMatter(), rows));
  for (const Axle& a : axles_)
    if (!a.suspension->getAssemblyTemplate().empty() && !registry_)
      registry_ = std::make_shared<PluginRegistry>(registry);  // for the copy makeInitialState assembles
  if (dense) {
    dense_ = new ReducedDenseRows(sc.getMatter(), sc.getForces());
    SimTK::Force::Custom(sc.updForces(), dense_);  // inactive until useDenseRows()
    auto service = std::make_shared<ConstraintRowsService>();
    const Scene* scene = scene_.get();
    const ReducedDenseRows* rows = dense_;
    service->use_simbody_rows = [scene, rows](SimTK::State& s) { useSimbodyRowsOf(*scene, rows, s); };
    // The formulation in effect decides (a scene that asks for "reduced" keeps
    // Simbody's rows). The vehicle owns the scene, and so this service, and
    // is not movable.
    service->use_dense_rows = [this](SimTK::State& s) {
      if (getFormulation().name == "dense") useDenseRows(s);
    };
    sc.setService<const ConstraintRowsService>(kConstraintRowsService, service);
  } else if (templates_.name == "reduced" && p_.formulation == "dense") {
    throw Error("vehicle formulation \"dense\": a reduced template has no dense rows");
  }
  addChassisOutputs(sc, chassis_);
}

int WheeledVehicle::axleIndex(const std::string& name) const {
  for (std::size_t i = 0; i < p_.axles.size(); ++i)
    if (p_.axles[i].name == name) return int(i);
  p_.axle(name);  // throws, listing the axles
  return -1;
}

void WheeledVehicle::requireSteerable(int axle, const std::string& plugin) const {
  if (!suspension(axle).isSteerable() && !rack(axle))
    throw Error("vehicle: steering plugin '" + plugin + "' steers axle '" + p_.axles[axle].name +
                "', whose knuckles its suspension's tie rods hold (tie_rod \"chassis\") and which has no rack");
}

double WheeledVehicle::overallSteeringRatio(int axle) const {
  if (!rack(axle)) throw Error("vehicle: axle '" + p_.axles.at(axle).name + "' has no rack (no \"steering\" block)");
  return axles_.at(axle).overall_ratio;
}

void WheeledVehicle::throwNotTemplate(int axle, const char* what) const {
  throw Error("vehicle axle '" + p_.axles.at(axle).name + "' has suspension template '" +
              suspension(axle).templateName() + "', not the one this needs (" + what + ")");
}

const SteeringPlugin& WheeledVehicle::addAxleSteering(const std::string& name, const std::string& axle,
                                                      std::shared_ptr<const SteeringCommand> command,
                                                      const std::string& commandAngle) {
  const int ax = axleIndex(axle);
  requireSteerable(ax, name);
  axleSteering_.push_back({name, axle, command, 0.0, commandAngle});
  auto plugin = std::make_unique<SteeringPlugin>(
      name, "chassis", std::vector<std::string>{cornerName(2 * ax) + ".knuckle", cornerName(2 * ax + 1) + ".knuckle"},
      std::move(command), suspension(ax).getSpinAxis(0));
  if (rack(ax)) plugin->driveRack(axle + ".rack", commandAngle);
  else if (commandAngle != "road_wheel")
    throw Error("vehicle: steering plugin '" + name + "': command_angle \"" + commandAngle + "\" needs a rack (axle '" +
                axle + "' has none)");
  return static_cast<const SteeringPlugin&>(scene_->addPlugin(std::move(plugin)));
}

SteeringPlugin& WheeledVehicle::addAxleSteering(const std::string& name, const std::string& axle,
                                                const SteeringStateSpec& state, const std::string& commandAngle) {
  const int ax = axleIndex(axle);
  requireSteerable(ax, name);
  axleSteering_.push_back({name, axle, nullptr, state.initial_angle_rad, commandAngle});
  auto plugin = std::make_unique<SteeringPlugin>(
      name, "chassis", std::vector<std::string>{cornerName(2 * ax) + ".knuckle", cornerName(2 * ax + 1) + ".knuckle"},
      state, suspension(ax).getSpinAxis(0));
  if (rack(ax)) plugin->driveRack(axle + ".rack", commandAngle);
  else if (commandAngle != "road_wheel")
    throw Error("vehicle: steering plugin '" + name + "': command_angle \"" + commandAngle + "\" needs a rack (axle '" +
                axle + "' has none)");
  return static_cast<SteeringPlugin&>(scene_->addPlugin(std::move(plugin)));
}

double WheeledVehicle::totalMass() const {
  double m = p_.chassis.mass_kg;
  for (const Axle& a : axles_) {
    for (int side = 0; side < 2; ++side) m += a.suspension->calcCornerMass(side);
    if (a.rack) m += a.rack->params().rack_mass_kg;  // sprung, carried by the chassis
  }
  return m;
}

int WheeledVehicle::degreesOfFreedom(const SimTK::State& s) const {
  scene_->getSystem().realize(s, SimTK::Stage::Instance);
  // A state-driven steering plugin's steer body moves by a prescribed acceleration.
  // (In a dense state the steering laws' rows stand for those Motions.)
  const int denseRows = dense_ && dense_->isActive(s) ? dense_->numConstraintRows() : 0;  // rows Simbody does not see
  return s.getNU() - s.getNUDotErr() - denseRows - static_cast<int>(steeringStateBodies(*scene_).size());
}

SimTK::State WheeledVehicle::makeInitialState(double speed, AssemblyReport* report) const {
  requireFinite(speed, "vehicle initial speed_m_s");
  const SimTK::MultibodySystem& system = scene_->getSystem();
  SimTK::State s = scene_->getDefaultState();
  const double road0 = makeRoad(p_.road)->height(0, 0, 0);
  // Each tire at its static deflection under an equal share of the weight; the
  // chassis at the mean of the heights that put each wheel there (written as
  // h_0 + mean(h_c - h_0), exactly h_0 when the corners agree).
  const int n = numCorners();
  const double fz = totalMass() * p_.gravity_m_per_s2 / n;
  auto cornerHeight = [&](int c) {
    const TireModel& tire = tires_[c]->getModel();
    return tire.vertical().unloaded_radius_m - calcStaticDeflection(tire, fz);
  };
  const TireModel& tire0 = tires_[0]->getModel();
  const double r0 = tire0.vertical().unloaded_radius_m, d0 = calcStaticDeflection(tire0, fz), h0 = r0 - d0;
  double dh = 0, wcz = 0;
  for (int c = 0; c < n; ++c) {
    dh += (cornerHeight(c) - h0) / n;
    wcz += suspension(c / 2).calcWheelCentreInChassis(c % 2)[2] / n;
  }
  chassis_.setQToFitTranslation(s, Vec3(0, 0, road0 + r0 - d0 + dh - wcz));
  system.realize(s, SimTK::Stage::Position);

  std::vector<std::pair<std::string, SimTK::MobilizedBody>> bodies;
  for (int c = 0; c < n; ++c)
    for (const std::string& role : suspension(c / 2).bodyRoles())
      bodies.push_back({cornerName(c) + "." + role, scene_->getBody(cornerName(c) + "." + role)});
  double gap = 0;
  AssemblyReport conReport;
  bool copied = false;
  // Axles that start from another template's assembly: a copy of the vehicle
  // with those templates, its axle steering held at its initial angles.
  WheeledVehicleParams cp = p_;
  cp.formulation = "constrained";  // every axle its constrained (assembly) template
  for (int ax = 0; ax < numAxles(); ++ax) copied = copied || !suspension(ax).getAssemblyTemplate().empty();
  if (copied) {
    WheeledVehicle con(cp, *registry_);
    for (const AxleSteering& a : axleSteering_)
      con.addAxleSteering(a.name, a.axle,
                          std::make_shared<HoldCommand>(a.command ? a.command->calcAt(s.getTime()).angle_rad
                                                                  : a.initial_angle_rad),
                          a.command_angle);
    // Steering plugins a scene file added through the registry (not through
    // addAxleSteering) are held in the copy the same way, in scene order:
    // without them the copy's knuckles assembled unsteered and the reduced
    // vehicle started elsewhere than the same composition in C++.
    for (const auto& plugin : scene_->getPlugins()) {
      const auto* sp = dynamic_cast<const SteeringPlugin*>(plugin.get());
      if (!sp || std::any_of(axleSteering_.begin(), axleSteering_.end(),
                             [&](const AxleSteering& a) { return a.name == sp->name(); }))
        continue;
      const double angle = sp->isStateDriven() ? sp->initialAngle() : sp->command().calcAt(s.getTime()).angle_rad;
      auto held = std::make_unique<SteeringPlugin>(sp->name(), sp->chassisBody(), sp->knuckleBodies(),
                                                   std::make_shared<HoldCommand>(angle), sp->spinAxis());
      if (sp->drivesRack()) held->driveRack(sp->rackBody(), sp->commandAngle());
      con.updScene().addPlugin(std::move(held));
    }
    const SimTK::State cs = con.makeInitialState(0.0, &conReport);
    chassis_.setQ(s, con.chassis().getQ(cs));
    for (int c = 0; c < n; ++c) {
      const Suspension& mine = suspension(c / 2);
      if (mine.getAssemblyTemplate().empty()) continue;
      const double delta = steeringAngle(cs, con.chassis(), con.getScene().getBody(cornerName(c) + ".knuckle"),
                                         mine.getSpinAxis(c % 2));
      mine.setPositionFrom(s, c % 2, con.suspension(c / 2), cs, delta);
    }
    gap = conReport.initial_loop_gap_m;
  }
  std::vector<SimTK::MobilizedBodyIndex> locked = {chassis_.getMobilizedBodyIndex()};
  for (int c = 0; c < n; ++c) {
    locked.push_back(scene_->getBody(cornerName(c) + ".wheel").getMobilizedBodyIndex());
    gap = std::max(gap, suspension(c / 2).calcLoopGap(s, c % 2));
  }
  for (auto mbx : steeringStateBodies(*scene_)) locked.push_back(mbx);  // keep delta at its initial value
  assembleLoops(system, s, locked, bodies, gap, "vehicle", report);
  if (copied && report) *report = conReport;  // the moves that made this configuration
  // Moving forward with every body at the chassis velocity and the wheels rolling.
  s.updU() = 0;
  chassis_.setUToFitLinearVelocity(s, Vec3(speed, 0, 0));
  system.realize(s, SimTK::Stage::Velocity);
  // Free rolling: each wheel spins at its own heading speed over its rolling radius
  // (assembly leaves a small toe on the knuckles, so headings differ slightly).
  std::vector<double> spin(n);
  for (int c = 0; c < n; ++c) {
    const ContactKinematics k = tires_[c]->calcContact(s).kinematics;
    spin[c] = k.vx_m_s / tires_[c]->getForceElement().getModel().calcRollingRadius(k.deflection_m);
  }
  for (int c = 0; c < n; ++c) scene_->getBody(cornerName(c) + ".wheel").setOneU(s, 0, spin[c]);
  system.realize(s, SimTK::Stage::Velocity);
  for (const TirePlugin* t : tires_) t->getForceElement().initializeRelaxationStates(s);
  if (getFormulation().name == "dense") {
    useDenseRows(s);
    system.realize(s, SimTK::Stage::Velocity);
  }
  return s;
}

const DoubleWishboneCorner& WheeledVehicle::corner(int c) const {
  const Suspension& s = suspension(c / 2);
  if (s.templateName() != "double_wishbone")
    throw Error("vehicle: corner() is the constrained double wishbone's; corner '" + cornerName(c) + "' is " +
                s.templateName() + " (reducedCorner() for double_wishbone_reduced)");
  return static_cast<const DoubleWishboneSuspension&>(s).getCorner(c % 2);
}

const ReducedWishboneCorner& WheeledVehicle::reducedCorner(int c) const {
  return suspensionAs<ReducedDoubleWishboneSuspension>(c / 2).getReducedCorner(c % 2);
}

bool WheeledVehicle::isReduced() const {
  for (const Axle& a : axles_)
    if (!dynamic_cast<const ReducedDoubleWishboneSuspension*>(a.suspension.get())) return false;
  return true;
}

const DoubleWishboneParams& WheeledVehicle::cornerParams(int c) const {
  return suspensionAs<DoubleWishboneSuspension>(c / 2).getCornerParams(c % 2);
}

double WheeledVehicle::suspensionAngle(const SimTK::State& s, int c) const {
  return suspension(c / 2).getSuspensionCoordinate(s, c % 2);
}

SimTK::State WheeledVehicle::makeStateLike(const WheeledVehicle& other, const SimTK::State& os) const {
  if (!isReduced())
    throw Error("vehicle: makeStateLike() builds a reduced model's state; every axle must be double_wishbone_reduced");
  const SimTK::MultibodySystem& system = scene_->getSystem();
  const Scene& osc = other.getScene();
  osc.getSystem().realize(os, SimTK::Stage::Velocity);
  SimTK::State s = scene_->getDefaultState();
  s.setTime(os.getTime());
  chassis_.setQ(s, other.chassis().getQ(os));
  chassis_.setU(s, other.chassis().getU(os));
  for (int c = 0; c < numCorners(); ++c) {
    const std::string n = cornerName(c);
    const ReducedWishboneCorner& rc = reducedCorner(c);
    const SimTK::MobilizedBody& ok = osc.getBody(n + ".knuckle");
    const SimTK::UnitVec3 spin = suspension(c / 2).getSpinAxis(c % 2);
    // (A.1) angle and its rate: x . f = -sin(delta), d/dt (x . f) = (w_K - w_C) . (f x x).
    const SimTK::Vec3 x = other.chassis().getBodyRotation(os).x();
    const SimTK::Vec3 f = ok.getBodyRotation(os) * spin.asVec3();
    const double delta = std::asin(-SimTK::dot(x, f));
    const double xfdot = SimTK::dot(ok.getBodyAngularVelocity(os) - other.chassis().getBodyAngularVelocity(os),
                                    SimTK::cross(f, x));
    const double sAng = other.suspensionAngle(os, c);
    setReducedCornerPosition(s, rc, sAng, delta);
    const double sRate = osc.getBody(n + ".lower_arm").getOneU(os, 0);
    const double deltaRate = -xfdot / std::cos(delta);
    rc.knuckle.setOneU(s, 0, sRate);
    rc.knuckle.setOneU(s, 1, deltaRate);
    rc.lower_arm.setOneU(s, 0, sRate);
    rc.upper_arm.setOneU(s, 0, rc.loop->calcUpperArmAngle(sAng)[1] * sRate);
    const SimTK::MobilizedBody& ow = osc.getBody(n + ".wheel");
    rc.wheel.setOneQ(s, 0, ow.getOneQ(os, 0));
    rc.wheel.setOneU(s, 0, ow.getOneU(os, 0));
  }
  // State-driven steer bodies (same plugins, same order) and z variables.
  const auto mine = steeringStateBodies(*scene_), theirs = steeringStateBodies(osc);
  if (mine.size() != theirs.size()) throw Error("vehicle makeStateLike: the vehicles have different steering plugins");
  for (std::size_t i = 0; i < mine.size(); ++i) {
    scene_->getMatter().getMobilizedBody(mine[i]).setOneQ(s, 0, osc.getMatter().getMobilizedBody(theirs[i]).getOneQ(os, 0));
    scene_->getMatter().getMobilizedBody(mine[i]).setOneU(s, 0, osc.getMatter().getMobilizedBody(theirs[i]).getOneU(os, 0));
  }
  if (s.getNZ() != os.getNZ()) throw Error("vehicle makeStateLike: the vehicles have different z variables");
  s.updZ() = os.getZ();
  system.realize(s, SimTK::Stage::Position);
  system.project(s, 1e-12);
  if (getFormulation().name == "dense") useDenseRows(s);
  system.realize(s, SimTK::Stage::Velocity);
  return s;
}

WheeledVehicle::Formulation WheeledVehicle::getFormulation() const {
  if (templates_.name != "reduced") return templates_;
  if (p_.formulation == "reduced") return templates_;
  if (p_.formulation == "dense") return {"dense", templates_.why};
  std::string whyNot;
  if (!collectDenseRows(nullptr, nullptr, nullptr, &whyNot)) return {"reduced", "not dense: " + whyNot};
  return {"dense", "every axle's template supports it"};
}

bool WheeledVehicle::collectDenseRows(std::vector<ReducedDenseRows::Arm>* arms,
                                      std::vector<ReducedDenseRows::Steer>* steers,
                                      std::vector<const SpeedHoldPlugin*>* speeds, std::string* whyNot) const {
  auto fail = [&](const std::string& why) {
    *whyNot = why;
    return false;
  };
  for (int ax = 0; ax < numAxles(); ++ax)
    if (!suspension(ax).supportsDenseRows())
      return fail("axle '" + p_.axles[ax].name + "''s template " + suspension(ax).templateName() + " has no dense rows");
  const Scene& sc = *scene_;
  for (int c = 0; c < numCorners(); ++c) {
    ReducedDenseRows::Arm arm;
    suspension(c / 2).getDenseArm(c % 2, &arm);
    if (arms) arms->push_back(arm);
  }
  int nRows = 2 * numCorners();
  for (const auto& plugin : sc.getPlugins()) {
    if (const auto* st = dynamic_cast<const SteeringPlugin*>(plugin.get())) {
      if (st->drivesRack()) return fail("steering plugin '" + plugin->name() + "' drives a rack");
      // Simbody projects its rows onto the new velocity level when a
      // command's rate jumps (the integrator restarts there); the dense rows
      // are only held by their Baumgarte terms and would lag the jump.
      if (st->sharedCommand() && !st->sharedCommand()->getRateJumpTimes().empty())
        return fail("steering plugin '" + plugin->name() + "''s command has rate jumps (the dense rows are not "
                    "projected at a jump)");
      if (sc.getBody(st->chassisBody()).getMobilizedBodyIndex() != chassis_.getMobilizedBodyIndex())
        return fail("steering plugin '" + plugin->name() + "' is not on the chassis");
      for (const std::string& k : st->knuckleBodies()) {
        int c = 0;
        while (c < numCorners() && cornerName(c) + ".knuckle" != k) ++c;
        if (c == numCorners()) return fail("steering plugin '" + plugin->name() + "' steers '" + k + "', not a knuckle");
        if ((st->spinAxis().asVec3() - suspension(c / 2).getSpinAxis(c % 2).asVec3()).norm() > 1e-12)
          return fail("steering plugin '" + plugin->name() + "' measures (A.1) about another spin axis than " + k + "'s");
        if (steers)
          steers->push_back({reducedCorner(c).knuckle, st->sharedCommand(),
                             st->isStateDriven() ? SimTK::MobilizedBody(st->getSteerBody()) : SimTK::MobilizedBody()});
        ++nRows;
      }
    } else if (const auto* sp = dynamic_cast<const SpeedHoldPlugin*>(plugin.get())) {
      if (sc.getBody(sp->chassisBody()).getMobilizedBodyIndex() != chassis_.getMobilizedBodyIndex())
        return fail("speed hold '" + plugin->name() + "' is not on the chassis");
      if (speeds) speeds->push_back(sp);
      ++nRows;
    }
  }
  // Every other constraint of the scene (another plugin's, a body lock's) is
  // one the dense system does not solve: one Constraint object per knuckle
  // row, one per speed hold, the vehicle's one ArmPlanesImpl.
  const int nConstraints = sc.getMatter().getNumConstraints();
  if (nConstraints != nRows - 2 * numCorners() + 1)
    return fail("the scene has " + std::to_string(nConstraints) + " constraint objects, the dense rows account for " +
                std::to_string(nRows - 2 * numCorners() + 1) + " (a plugin adds a constraint the dense system does "
                "not solve)");
  return true;
}

void WheeledVehicle::useDenseRows(SimTK::State& s) const {
  std::vector<ReducedDenseRows::Arm> arms;
  std::vector<ReducedDenseRows::Steer> steers;
  std::vector<const SpeedHoldPlugin*> holds;
  std::string whyNot;
  const std::string why = " (the dense rows solve steering of the knuckles, time-commanded or state-driven, and "
                          "speed holds on the chassis; use formulation \"reduced\" or \"constrained\")";
  if (!collectDenseRows(&arms, &steers, &holds, &whyNot)) throw Error("vehicle: dense forward dynamics: " + whyNot + why);
  const Scene& sc = *scene_;
  // Every state-driven steering's delta'' is a row of the dense system (its
  // Motion disabled below), solved with its law (reduced_dense.h).
  std::vector<ReducedDenseRows::Law> laws;
  std::vector<const SteeringPlugin*> lawPlugins;
  for (const auto& plugin : sc.getPlugins())
    if (const auto* st = dynamic_cast<const SteeringPlugin*>(plugin.get()); st && st->isStateDriven()) {
      const ReducedDenseRows* dense = dense_;
      const int k = int(laws.size());
      st->setExternalSolve({[dense](const SimTK::State& x) { return dense->isActive(x); },
                            [dense, k](const SimTK::State& x) { return dense->solvedSteerAcceleration(x, k); }});
      laws.push_back({st});
      lawPlugins.push_back(st);
    }
  std::vector<ReducedDenseRows::Speed> speeds;
  for (const SpeedHoldPlugin* sp : holds) {
    const ReducedDenseRows* dense = dense_;
    const int k = int(speeds.size());
    sp->setExternalRow({[dense](const SimTK::State& st) { return dense->isActive(st); },
                        [dense, k](const SimTK::State& st) { return dense->speedHoldForce(st, k); },
                        [dense, k](SimTK::State& st, bool on) { dense->setSpeedHoldEnabled(st, k, on); }});
    speeds.push_back({chassis_, sp});
  }
  dense_->setRows(std::move(arms), std::move(steers), std::move(speeds), std::move(laws));
  const SimTK::MultibodySystem& system = sc.getSystem();
  if (dense_->isActive(s)) return;
  system.realize(s, SimTK::Stage::Instance);
  if (s.getNUDotErr() != dense_->numConstraintRows())
    throw Error("vehicle: the scene has " + std::to_string(s.getNUDotErr()) + " constraint rows, the dense path solves " +
                std::to_string(dense_->numConstraintRows()) + why);
  const SimTK::SimbodyMatterSubsystem& m = sc.getMatter();
  for (SimTK::ConstraintIndex cx(0); cx < m.getNumConstraints(); ++cx) m.getConstraint(cx).disable(s);
  for (const SteeringPlugin* st : lawPlugins) st->getSteerBody().getMotion().disable(s);
  dense_->setActive(s, true);
}

namespace {
/// WheeledVehicle::useSimbodyRows on the scene and its dense element (the
/// scene service holds these, not the vehicle: both live on the heap).
void useSimbodyRowsOf(const Scene& scene, const ReducedDenseRows* dense, SimTK::State& s) {
  if (!dense || !dense->isActive(s)) return;
  std::vector<bool> released;
  int k = 0;
  for (const auto& plugin : scene.getPlugins())
    if (dynamic_cast<const SpeedHoldPlugin*>(plugin.get())) released.push_back(!dense->isSpeedHoldEnabled(s, k++));
  dense->setActive(s, false);
  const SimTK::SimbodyMatterSubsystem& m = scene.getMatter();
  for (SimTK::ConstraintIndex cx(0); cx < m.getNumConstraints(); ++cx) m.getConstraint(cx).enable(s);
  for (const auto& plugin : scene.getPlugins())
    if (const auto* st = dynamic_cast<const SteeringPlugin*>(plugin.get()); st && st->isStateDriven() && !st->drivesRack())
      st->getSteerBody().getMotion().enable(s);
  k = 0;
  for (const auto& plugin : scene.getPlugins())
    if (const auto* sp = dynamic_cast<const SpeedHoldPlugin*>(plugin.get()))
      if (released[k++]) sp->setEnabled(s, false);
}
}  // namespace

void WheeledVehicle::useSimbodyRows(SimTK::State& s) const { useSimbodyRowsOf(*scene_, dense_, s); }

}  // namespace vdyn
