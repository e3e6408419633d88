// Scene-file adaptors of the built-in vehicles: each owns the concrete vehicle
// (QuarterCar, Bicycle, WheeledVehicle) and exposes its scene, attachments and
// initial state through vdyn::Vehicle.
#include "vdyn/vehicles/scene_vehicles.h"

#include "vdyn/vehicles/bicycle.h"
#include "vdyn/vehicles/wheeled_vehicle.h"
#include "vdyn/templates/rack_and_pinion.h"
#include "vdyn/vehicles/quarter_car.h"

namespace vdyn {

namespace {

std::string axisText(const SimTK::Vec3& a) {
  return formatValue(a[0]) + " " + formatValue(a[1]) + " " + formatValue(a[2]);
}

/// Scene keys every vehicle takes (read by the scene loader).
std::vector<FieldInfo> sceneVehicleKeys() {
  return {{"data", "-", "required", "vehicle data file (resolved from the scene file's folder, then the data path)"},
          {"overrides", "-", "{}", "object merged over the data file (JSON merge patch): change a value inline"},
          {"initial_speed_m_s", "m/s", "0", "forward speed of the initial state (wheels rolling)"}};
}

class WheeledSceneVehicle : public Vehicle {
 public:
  WheeledSceneVehicle(const std::string& type, const VehicleSpec& spec)
      : Vehicle(type), car_(WheeledVehicleParams::fromParams(spec.data, spec.registry), *spec.registry) {
    attachments_["chassis"] = {{"chassis", "chassis"}};
    std::string wheels;
    for (int c = 0; c < car_.numCorners(); ++c) wheels += (c ? "," : "") + car_.cornerName(c) + ".wheel";
    attachments_["wheels"] = {{"chassis", "chassis"}, {"wheels", wheels}};
    for (int ax = 0; ax < car_.numAxles(); ++ax) {
      const std::string r = car_.cornerName(2 * ax), l = car_.cornerName(2 * ax + 1);
      // An axle whose knuckles a tie rod holds offers no knuckles to steer.
      Attachment a = {{"chassis", "chassis"}, {"spin_axis", axisText(car_.suspension(ax).getSpinAxis(0))}};
      if (car_.suspension(ax).isSteerable()) a["knuckles"] = r + ".knuckle," + l + ".knuckle";
      // An axle on a rack: a steering plugin attached to it drives the rack
      // (typed role "rack") and measures the knuckles.
      if (car_.rack(ax)) {
        a["knuckles"] = r + ".knuckle," + l + ".knuckle";
        a["rack"] = car_.params().axles[ax].name + ".rack";
      }
      attachments_[car_.params().axles[ax].name + "_axle"] = a;
    }
    for (int c = 0; c < car_.numCorners(); ++c) {
      const std::string n = car_.cornerName(c);
      attachments_[n] = {{"chassis", "chassis"},
                         {"wheel", n + ".wheel"},
                         {"knuckle", n + ".knuckle"},
                         {"spin_axis", axisText(car_.suspension(c / 2).getSpinAxis(c % 2))}};
      if (car_.suspension(c / 2).isSteerable()) attachments_[n]["knuckles"] = n + ".knuckle";
    }
  }

 protected:
  void* DoGetConcrete(const std::type_info& t) override { return t == typeid(WheeledVehicle) ? &car_ : nullptr; }
  Scene& DoUpdScene() override { return car_.updScene(); }
  SimTK::State DoMakeInitialState(double speed) const override {
    return car_.makeInitialState(speed, &assembly_);
  }
  Json DoDescribe(const SimTK::State& s) const override {
    Json templates = Json::object();
    for (int ax = 0; ax < car_.numAxles(); ++ax)
      templates[car_.params().axles[ax].name] = car_.suspension(ax).templateName();
    // The formulation that ran: dense exactly when the state's dense rows are on.
    const WheeledVehicle::Formulation f = car_.getFormulation();
    return {{"total_mass_kg", car_.totalMass()},
            {"dof", car_.degreesOfFreedom(s)},
            {"assembly_max_body_move_m", assembly_.max_move_m},
            {"suspensions", templates},
            {"formulation", f.name},
            {"formulation_why", f.why}};
  }

 private:
  WheeledVehicle car_;
  mutable AssemblyReport assembly_;
};

class BicycleSceneVehicle : public Vehicle {
 public:
  BicycleSceneVehicle(const VehicleSpec& spec)
      : Vehicle("bicycle"), bike_(BicycleParams::fromParams(spec.data), *spec.registry) {
    attachments_["chassis"] = {{"chassis", "chassis"}};
    attachments_["front_axle"] = {{"chassis", "chassis"}, {"knuckles", "fork"}, {"wheel", "front_axle"}};
    attachments_["rear_axle"] = {{"chassis", "chassis"}, {"wheel", "rear_axle"}};
    attachments_["wheels"] = {{"chassis", "chassis"}, {"wheels", "front_axle,rear_axle"}};
  }

 protected:
  void* DoGetConcrete(const std::type_info& t) override { return t == typeid(Bicycle) ? &bike_ : nullptr; }
  Scene& DoUpdScene() override { return bike_.updScene(); }
  SimTK::State DoMakeInitialState(double speed) const override { return bike_.makeInitialState(speed); }
  Json DoDescribe(const SimTK::State& s) const override {
    return {{"total_mass_kg", bike_.totalMass()},
            {"dof", bike_.degreesOfFreedom(s)},
            {"front_axle_distance_m", bike_.distanceToFrontAxle()},
            {"rear_axle_distance_m", bike_.distanceToRearAxle()}};
  }

 private:
  Bicycle bike_;
};

class QuarterCarSceneVehicle : public Vehicle {
 public:
  QuarterCarSceneVehicle(const VehicleSpec& spec)
      : Vehicle("quarter_car"),
        car_(QuarterCarParams::fromParams(spec.data, spec.registry), *spec.registry),
        rideHeightSpring_(spec.data.json().value("spring_free_length_from_ride_height", false)) {
    attachments_["chassis"] = {{"chassis", "chassis"}};
    attachments_["corner"] = {{"chassis", "chassis"}, {"wheel", "wheel"}, {"knuckle", "knuckle"}};
  }

 protected:
  void* DoGetConcrete(const std::type_info& t) override { return t == typeid(QuarterCar) ? &car_ : nullptr; }
  Scene& DoUpdScene() override { return car_.updScene(); }
  SimTK::State DoMakeInitialState(double speed) const override {
    if (speed != 0)
      throw Error("quarter_car: initial_speed_m_s must be 0 (the chassis moves only vertically), got " +
                  formatValue(speed));
    return car_.makeInitialState(true, &assembly_);
  }
  Json DoDescribe(const SimTK::State& s) const override {
    return {{"total_mass_kg", car_.totalMass()},
            {"dof", car_.degreesOfFreedom(s)},
            {"assembly_max_body_move_m", assembly_.max_move_m},
            {"assembly_initial_loop_gap_m", assembly_.initial_loop_gap_m}};
  }
  /// The spring free length the ride-height rule set, as data.
  Json DoGetDerivedData() const override {
    if (!rideHeightSpring_) return Json::object();
    return {{"spring_free_length_from_ride_height", false},
            {"corner_overrides", {{"spring", {{"free_length_m", car_.params().corner.spring_free_length_m}}}}}};
  }

 private:
  QuarterCar car_;
  bool rideHeightSpring_;
  mutable AssemblyReport assembly_;
};

/// The scene keys of a vehicle entry, then the vehicle data's keys (the table
/// the builder reads the data with) as "data: <key>".
template <class P>
TypeInfo info(const std::string& summary, const FieldTable<P>& data) {
  TypeInfo t{summary, sceneVehicleKeys()};
  for (auto f : data.describe()) {
    f.key = "data: " + f.key;
    t.fields.push_back(std::move(f));
  }
  return t;
}

}  // namespace

void registerVehicles(PluginRegistry& registry) {
  registerSuspensionTemplates(registry);
  registerAntiRollBarTemplates(registry);
  registerSteeringTemplates(registry);
  for (const char* type : {"wheeled", "fourws"}) {
    TypeInfo t = info(std::string(type) == "fourws"
                          ? "the wheeled vehicle under the App. A car's name (kept so scenes naming it keep working)"
                          : "wheeled vehicle: a free chassis and axles composed from templates (suspension per axle, "
                            "tire per axle); attachments chassis, wheels, <axle>_axle (front_axle, ...), each corner "
                            "(rf, lf, ...)",
                      WheeledVehicleParams::fields());
    registry.addVehicle(
        type, [type](const VehicleSpec& s) { return std::make_unique<WheeledSceneVehicle>(type, s); }, std::move(t));
  }
  registry.addVehicle(
      "bicycle", [](const VehicleSpec& s) { return std::make_unique<BicycleSceneVehicle>(s); },
      info("nonlinear bicycle (section 7.1): free chassis, steered fork, two axles of two tires; attachments "
           "chassis, front_axle, rear_axle",
           BicycleParams::fields()));
  registry.addVehicle(
      "quarter_car", [](const VehicleSpec& s) { return std::make_unique<QuarterCarSceneVehicle>(s); },
      info("chapter 4 quarter car: App. A corner under a chassis on a vertical slider; attachments chassis, corner",
           QuarterCarParams::fields()));
}

}  // namespace vdyn
