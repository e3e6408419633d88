#include "vdyn/tire/tire_force.h"

#include <cmath>

namespace vdyn {

using SimTK::Vec3;

TireForceImpl::TireForceImpl(const SimTK::MobilizedBody& wheel, std::shared_ptr<const TireModel> model,
                             std::shared_ptr<const Road> road, const SimTK::UnitVec3& spinAxis_W,
                             const Vec3& centre_W)
    : TireForceImpl(wheel, std::move(model), std::move(road), spinAxis_W, centre_W, centre_W) {}

TireForceImpl::TireForceImpl(const SimTK::MobilizedBody& wheel, std::shared_ptr<const TireModel> model,
                             std::shared_ptr<const Road> road, const SimTK::UnitVec3& spinAxis_W,
                             const Vec3& centre_W, const Vec3& slipCentre_W)
    : wheel_(wheel),
      model_(std::move(model)),
      road_(std::move(road)),
      spinAxis_W_(spinAxis_W),
      centre_W_(centre_W),
      slipCentre_W_(slipCentre_W) {
  if (!model_) throw Error("tire force element: no tire model");
  if (!road_) throw Error("tire force element: no road");
  // The centre must lie on the spin axis, or spinning would move it.
  for (const Vec3& c : {centre_W_, slipCentre_W_})
    if ((c - SimTK::dot(c, Vec3(spinAxis_W_)) * Vec3(spinAxis_W_)).norm() > 1e-12)
      throw Error("tire centre_m and slip_centre_m must lie on the wheel's spin axis");
}

TireForceImpl::Geometry TireForceImpl::calcGeometry(const SimTK::State& s) const {
  Geometry g;
  const SimTK::Transform& X_GW = wheel_.getBodyTransform(s);
  const Vec3 p_GW = X_GW * centre_W_;  // tire centre
  const Vec3 s_G = X_GW.R() * Vec3(spinAxis_W_);
  const double t = s.getTime();
  const Vec3 n = Vec3(road_->normal(p_GW[0], p_GW[1], t));
  // Direction in the wheel plane pointing most steeply into the road.
  const double ns = SimTK::dot(n, s_G);
  Vec3 down = -n + ns * s_G;
  const double len = down.norm();
  if (len < 1e-9) return g;  // wheel lying flat on the road: no rolling contact
  down /= len;
  const TireVerticalParams& p = model_->vertical();
  const Vec3 p_GC0 = p_GW + (p.unloaded_radius_m - p.carcass_radius_m) * down;  // carcass centre
  const double h = road_->height(p_GC0[0], p_GC0[1], t);
  const double clearance = (p_GC0[2] - h) * n[2];  // height of C0 above the road along n
  g.deflection = p.carcass_radius_m - clearance;
  if (!(g.deflection > 0)) return g;
  g.p_GC = p_GC0 - clearance * n;  // point on the road surface under the carcass centre
  const Vec3 x = SimTK::cross(s_G, n) / len;  // heading (|s x n| = len)
  g.R_GC = SimTK::Rotation(SimTK::Mat33(x, SimTK::cross(n, x), n), true);
  g.camber = std::asin(std::max(-1.0, std::min(1.0, -ns)));
  g.in_contact = true;
  return g;
}

void TireForceImpl::realizeTopology(SimTK::State& s) const {
  if (!hasRelaxationStates()) return;
  if (!zSub_) throw Error("tire force element with relaxation lengths needs a state subsystem (setStateSubsystem)");
  z0_ = zSub_->allocateZ(s, SimTK::Vector(2, 0.0));
}

TireContact TireForceImpl::calcContact(const SimTK::State& s) const {
  TireContact c = calcContactKinematics(s);
  if (!c.in_contact) return c;
  if (hasRelaxationStates()) {
    const SimTK::Vector& z = zSub_->getZ(s);
    ContactKinematics& k = c.kinematics;
    const auto [sigmaX, sigmaY] = model_->calcRelaxationLengths(model_->calcNormalForce(k));
    k.transient_slip = true;
    if (sigmaX > 0) k.kappa = -z[z0_] / sigmaX;
    if (sigmaY > 0) k.tan_alpha = z[z0_ + 1] / sigmaY;
  }
  c.forces = model_->calcForces(c.kinematics);
  return c;
}

SimTK::Vec2 TireForceImpl::calcRelaxationRates(const SimTK::State& s) const {
  SimTK::Vec2 rate(0);
  if (!hasRelaxationStates()) return rate;
  const TireContact c = calcContactKinematics(s);
  const auto [sigmaX, sigmaY] = model_->calcRelaxationLengths(model_->calcNormalForce(c.kinematics));
  const SimTK::Vector& z = zSub_->getZ(s);
  // du/dt = v_slip - |Vx| u / sigma: the patch follows the slip displacement
  // and relaxes to u = sigma v_slip / |Vx| (Pacejka's first-order transient).
  // Off the ground the patch relaxes at the wheel's speed (or at rest, stays).
  const ContactKinematics& k = c.kinematics;
  const double V = std::abs(k.vx_m_s);
  const double vsx = c.in_contact ? k.vx_m_s - k.spin_rad_s * model_->calcRollingRadius(k.deflection_m) : 0.0;
  const double vsy = c.in_contact ? k.vy_m_s : 0.0;
  if (sigmaX > 0) rate[0] = vsx - V * z[z0_] / sigmaX;
  if (sigmaY > 0) rate[1] = vsy - V * z[z0_ + 1] / sigmaY;
  return rate;
}

void TireForceImpl::realizeDynamics(const SimTK::State& s) const {
  if (!hasRelaxationStates()) return;
  const SimTK::Vec2 rate = calcRelaxationRates(s);
  SimTK::Vector& zdot = zSub_->updZDot(s);
  zdot[z0_] = rate[0];
  zdot[z0_ + 1] = rate[1];
}

void TireForceImpl::initializeRelaxationStates(SimTK::State& s) const {
  if (!hasRelaxationStates()) return;
  const TireContact c = calcContactKinematics(s);
  const ContactKinematics& k = c.kinematics;
  const auto [sigmaX, sigmaY] = model_->calcRelaxationLengths(model_->calcNormalForce(k));
  const double den = std::max(std::abs(k.vx_m_s), model_->slip().low_speed_threshold_m_s);
  const double vsx = c.in_contact ? k.vx_m_s - k.spin_rad_s * model_->calcRollingRadius(k.deflection_m) : 0.0;
  const double vsy = c.in_contact ? k.vy_m_s : 0.0;
  SimTK::Vector& z = zSub_->updZ(s);
  z[z0_] = sigmaX * vsx / den;
  z[z0_ + 1] = sigmaY * vsy / den;
}

TireContact TireForceImpl::calcContactKinematics(const SimTK::State& s) const {
  TireContact c;
  const Geometry g = calcGeometry(s);
  if (!g.in_contact) return c;
  c.in_contact = true;
  c.p_GC = g.p_GC;
  c.R_GC = g.R_GC;
  const double deflection = g.deflection, camber = g.camber;
  const Vec3 p_GW = wheel_.findStationLocationInGround(s, centre_W_);  // tire centre
  const Vec3 v_GW = wheel_.findStationVelocityInGround(s, centre_W_);
  const Vec3 v_slip = slipCentre_W_ == centre_W_ ? v_GW : wheel_.findStationVelocityInGround(s, slipCentre_W_);
  const Vec3 w_GW = wheel_.getBodyAngularVelocity(s);
  const Vec3 s_G = wheel_.getBodyRotation(s) * Vec3(spinAxis_W_);
  const Vec3 n = c.R_GC.z();
  // Velocity of the wheel material point at the contact point; its normal
  // component is the rate of change of the deflection (the contact point is an
  // extremum of the wheel's height, so its material and geometric rates agree).
  const Vec3 v_GP = v_GW + SimTK::cross(w_GW, c.p_GC - p_GW);
  ContactKinematics& k = c.kinematics;
  k.deflection_m = deflection;
  k.deflection_rate_m_s = -(SimTK::dot(v_GP, n) - road_->heightRate(c.p_GC[0], c.p_GC[1], s.getTime()));
  k.vx_m_s = SimTK::dot(v_slip, c.R_GC.x());
  k.vy_m_s = SimTK::dot(v_slip, c.R_GC.y());
  k.spin_rad_s = SimTK::dot(w_GW, s_G);
  k.camber_rad = camber;
  return c;
}

void TireForceImpl::calcForce(const SimTK::State& s, SimTK::Vector_<SimTK::SpatialVec>& bodyForces,
                              SimTK::Vector_<Vec3>&, SimTK::Vector&) const {
  const TireContact c = calcContact(s);
  if (!c.in_contact) return;
  const TireForces& f = c.forces;
  const Vec3 F_G = c.R_GC * Vec3(f.fx_N, f.fy_N, f.fz_N);
  const Vec3 s_G = wheel_.getBodyRotation(s) * Vec3(spinAxis_W_);
  Vec3 M_G = f.mz_N_m * c.R_GC.z() + f.my_N_m * s_G;
  if (f.mx_N_m != 0) M_G += f.mx_N_m * c.R_GC.x();
  const Vec3 r_GP = c.p_GC - wheel_.getBodyOriginLocation(s);  // moment about the body origin
  bodyForces[wheel_.getMobilizedBodyIndex()] += SimTK::SpatialVec(M_G + SimTK::cross(r_GP, F_G), F_G);
}

SimTK::Real TireForceImpl::calcPotentialEnergy(const SimTK::State& s) const {
  const Geometry g = calcGeometry(s);
  return g.in_contact ? model_->calcPotentialEnergy(g.deflection) : 0.0;
}

// ---------------------------------------------------------------------------
TirePlugin::TirePlugin(std::string type, std::string name, std::string wheelBody,
                       std::shared_ptr<const TireModel> model, SimTK::UnitVec3 spinAxis_W,
                       std::string roadService, SimTK::Vec3 centre_W)
    : ForceElementPlugin(std::move(type), std::move(name)),
      wheelBody_(std::move(wheelBody)),
      model_(std::move(model)),
      spinAxis_W_(spinAxis_W),
      roadService_(std::move(roadService)),
      centre_W_(centre_W) {
  if (!model_) throw Error("tire plugin '" + this->name() + "': no tire model");
}

TirePlugin& TirePlugin::setSlipCentre(const SimTK::Vec3& slipCentre_W) {
  if (impl_) throw Error("tire plugin '" + name() + "': set the slip centre before adding it to a scene");
  slipCentre_W_ = slipCentre_W;
  return *this;
}

const TireForceImpl& TirePlugin::getForceElement() const {
  if (!impl_) throw Error("tire plugin '" + name() + "' is not part of a scene yet");
  return *impl_;
}

void TirePlugin::DoAddTo(Scene& scene) {
  const SimTK::MobilizedBody& wheel = scene.getBody(wheelBody_);
  auto road = scene.getService<const Road>(roadService_);
  auto* impl = new TireForceImpl(wheel, model_, road, spinAxis_W_, centre_W_, slipCentre_W_.value_or(centre_W_));
  impl->setStateSubsystem(scene.updForces());
  SimTK::Force::Custom(scene.updForces(), impl);  // the subsystem owns impl
  impl_ = impl;
  const TireForceImpl* e = impl;
  auto add = [&](const std::string& q, const std::string& unit, auto get) {
    scene.addOutput(Output{name() + "." + q, unit, SimTK::Stage::Velocity,
                           [e, get](const SimTK::State& s) { return get(e->calcContact(s)); }});
  };
  add("Fx_N", "N", [](const TireContact& c) { return c.forces.fx_N; });
  add("Fy_N", "N", [](const TireContact& c) { return c.forces.fy_N; });
  add("Fz_N", "N", [](const TireContact& c) { return c.forces.fz_N; });
  add("Mz_N_m", "N m", [](const TireContact& c) { return c.forces.mz_N_m; });
  add("deflection_m", "m", [](const TireContact& c) { return c.kinematics.deflection_m; });
  add("slip_ratio", "1", [](const TireContact& c) { return c.forces.slip_ratio; });
  add("slip_angle_rad", "rad", [](const TireContact& c) { return c.forces.slip_angle_rad; });
}

TireChoice TireChoice::fromParams(const ParamReader& base, const ParamReader* overrides) {
  TireChoice c;
  c.plugin = base.string("plugin");
  c.where = base.where();
  ParamReader params = base.has("params") ? base.child("params") : ParamReader::fromJson(Json::object(), base.where() + ".params");
  if (overrides) {
    const std::string kind = overrides->stringOr("plugin", c.plugin);
    if (kind != c.plugin) {  // another kind: the base's params are another kind's keys
      params.markAllRead();
      params = ParamReader::fromJson(Json::object(), overrides->where() + ".params");
      c.where = overrides->where();
    }
    c.plugin = kind;
    if (overrides->has("params")) {
      params = params.mergedWith(overrides->child("params"));
      c.where = overrides->where();
    }
    overrides->requireAllKeysRead();
  }
  if (c.plugin.empty()) throw Error(c.where + ".plugin: empty tire plugin name");
  if (!params.json().is_object()) throw Error(c.where + ".params: must be an object");
  c.params = params.json();
  params.markAllRead();  // read by the kind's factory when the vehicle adds the tire
  base.requireAllKeysRead();
  return c;
}

double& TireChoice::updNumber(const std::string& key) {
  auto it = params.find(key);
  if (it == params.end() || !it->is_number())
    throw Error(where + ".params." + key + ": a design parameter needs this number given in the tire's params");
  if (!it->is_number_float()) *it = it->get<double>();
  return it->get_ref<double&>();
}

TireChoice TireChoice::linearised() const {
  if (plugin != "gim" && plugin != "fiala")
    throw Error(where + ".plugin: only a brush tire (gim, fiala) has a linearisation, got '" + plugin + "'");
  TireChoice c = *this;
  c.plugin = "linear";
  c.params = LinearTireParams::linearised(BrushTireParams::fromParams(ParamReader::fromJson(params, where + ".params")))
                 .toJson();
  return c;
}

double TireChoice::getNumber(const std::string& key) const {
  auto it = params.find(key);
  if (it != params.end() && it->is_number()) return it->get<double>();
  if (it == params.end()) {  // a built-in kind's default
    std::vector<FieldInfo> fields;
    if (plugin == "gim" || plugin == "fiala") fields = BrushTireParams::fields().describe();
    if (plugin == "linear") fields = LinearTireParams::fields().describe();
    for (const FieldInfo& f : fields)
      if (f.key == key) return Json::parse(f.default_value).get<double>();
  }
  throw Error(where + ".params." + key + ": not a number of tire '" + plugin + "'");
}

PluginSpec TireChoice::makeSpec(const std::string& name, const std::string& wheel, const Json& entry) const {
  // Read as the data file's block: the factory's messages name where.params.KEY.
  Json j = entry;
  j["params"] = params;
  auto root = std::make_shared<const Json>(std::move(j));
  return PluginSpec{name, ParamReader(root, root.get(), where), {{"wheel", wheel}}};
}

double calcStaticDeflection(const TireModel& model, double fz) { return fz / model.vertical().radial_stiffness_N_per_m; }

void registerTirePlugins(PluginRegistry& registry) {
  // The brush and linear laws are symmetric: the wheel's side does not matter.
  registerTireKind<BrushTireParams>(
      registry, "gim", "the seed's analytical comprehensive-slip tire (Gim and Nikravesh) on a wheel body",
      [](const BrushTireParams& p, WheelSide) { return std::make_shared<GimTire>(p); });
  registerTireKind<BrushTireParams>(registry, "fiala", "the Fiala tire as published, on a wheel body",
                                    [](const BrushTireParams& p, WheelSide) { return std::make_shared<FialaTire>(p); });
  registerTireKind<LinearTireParams>(
      registry, "linear", "linear tire Fx = C_s kappa, Fy = -C_a alpha (no saturation), on a wheel body",
      [](const LinearTireParams& p, WheelSide) { return std::make_shared<LinearTire>(p); });
}

SteadyTire SteadyTire::fromData(const std::string& data, const PluginRegistry& registry) {
  TireChoice tire;
  const bool tir = data.size() > 4 && data.substr(data.size() - 4) == ".tir";
  if (tir) {
    tire.plugin = "magic_formula";
    tire.params = Json{{"file", data}};
    tire.where = data;
  } else {
    const ParamReader r = ParamReader::fromFile(data);
    tire = TireChoice::fromParams(r.child("tire"));
    r.markAllRead();  // only the tire block of a vehicle data file is used
  }
  SteadyTire t;
  t.kind = tire.plugin;
  t.plugin = registry.create(PluginKind::ForceElement, tire.plugin, tire.makeSpec("tire", "wheel"), data);
  const auto* tp = dynamic_cast<const TirePlugin*>(t.plugin.get());
  if (!tp) throw Error(data + ": plugin '" + tire.plugin + "' is not a tire");
  t.model = &tp->getModel();
  return t;
}

TireForces SteadyTire::calcForces(double fz_N, double alpha_rad, double kappa, double gamma_rad, double vx_m_s) const {
  ContactKinematics k;
  k.deflection_m = calcStaticDeflection(*model, fz_N);
  k.vx_m_s = vx_m_s;
  k.vy_m_s = vx_m_s * std::tan(alpha_rad);
  k.spin_rad_s = vx_m_s * (1 + kappa) / model->calcRollingRadius(k.deflection_m);
  k.camber_rad = gamma_rad;
  return model->calcForces(k);
}

}  // namespace vdyn
