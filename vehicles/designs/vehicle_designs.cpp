#include "vdyn/vehicles/vehicle_designs.h"


namespace vdyn {

template <class P>
static std::vector<DesignParameter> paramsOf(const std::vector<FieldHandle<P>>& h, P nominal) {
  std::vector<DesignParameter> v;
  for (const auto& f : h) {
    DesignParameter d = f.param;
    d.nominal = f.field(nominal);
    v.push_back(d);
  }
  return v;
}

static std::vector<FieldHandle<QuarterCarParams>> quarterCarHandles() {
  using P = QuarterCarParams;
  using H = FieldHandle<P>;
  std::vector<H> h = {
      // The seed's b = [m1, m3, K, D, Cz, s'] (section 4.6.4).
      {{"chassis_mass_kg", "m1", "kg", 0, 100}, [](P& p) -> double& { return p.chassis_mass_kg; }},
      {{"corner.knuckle.mass_kg", "m3", "kg", 0, 5}, [](P& p) -> double& { return p.corner.knuckle.mass_kg; }},
      {{"corner.spring.stiffness_N_per_m", "K", "N/m", 0, 1e4},
       [](P& p) -> double& { return p.corner.spring_stiffness_N_per_m; }},
      {{"corner.spring.damping_N_s_per_m", "D", "N s/m", 0, 1e3},
       [](P& p) -> double& { return p.corner.damper_N_s_per_m; }},
      {{"tire.radial_stiffness_N_per_m", "Cz", "N/m", 0, 1e5},
       [](P& p) -> double& { return p.tire.updNumber("radial_stiffness_N_per_m"); }},
      // s' = 0 nominal: perturbations scale with 0.01 m.
      {{"upper_pivot_offset_m", "s'", "m", 0, 0.01}, [](P& p) -> double& { return p.upper_pivot_offset_m; }},
      // More for the scaling study (20 in all).
      {{"corner.lower_arm.mass_kg", "m2", "kg", 0, 0.5}, [](P& p) -> double& { return p.corner.lower_arm.mass_kg; }},
      {{"corner.upper_arm.mass_kg", "m4", "kg", 0, 0.5}, [](P& p) -> double& { return p.corner.upper_arm.mass_kg; }},
      {{"corner.wheel.mass_kg", "mw", "kg", 0, 10}, [](P& p) -> double& { return p.corner.wheel.mass_kg; }},
      {{"corner.knuckle.inertia_kg_m2[0]", "", "kg m^2", 0, 1},
       [](P& p) -> double& { return p.corner.knuckle.inertia_kg_m2[0]; }},
      {{"corner.knuckle.inertia_kg_m2[1]", "", "kg m^2", 0, 1},
       [](P& p) -> double& { return p.corner.knuckle.inertia_kg_m2[1]; }},
      {{"corner.knuckle.inertia_kg_m2[2]", "", "kg m^2", 0, 1},
       [](P& p) -> double& { return p.corner.knuckle.inertia_kg_m2[2]; }},
      {{"corner.wheel.inertia_kg_m2[0]", "", "kg m^2", 0, 1},
       [](P& p) -> double& { return p.corner.wheel.inertia_kg_m2[0]; }},
      {{"corner.wheel.inertia_kg_m2[2]", "", "kg m^2", 0, 1},
       [](P& p) -> double& { return p.corner.wheel.inertia_kg_m2[2]; }},
      {{"corner.spring.free_length_m", "l0", "m", 0, 0.1},
       [](P& p) -> double& { return p.corner.spring_free_length_m; }},
      {{"corner.spring.chassis_point_m[0]", "", "m", 0, 0.1},
       [](P& p) -> double& { return p.corner.spring_chassis_point_m[0]; }},
      {{"corner.spring.chassis_point_m[1]", "", "m", 0, 0.1},
       [](P& p) -> double& { return p.corner.spring_chassis_point_m[1]; }},
      {{"corner.spring.chassis_point_m[2]", "", "m", 0, 0.1},
       [](P& p) -> double& { return p.corner.spring_chassis_point_m[2]; }},
      {{"tire.radial_damping_N_s_per_m", "", "N s/m", 0, 100},
       [](P& p) -> double& { return p.tire.updNumber("radial_damping_N_s_per_m"); }},
      {{"tire.cornering_stiffness_N_per_rad", "", "N/rad", 0, 1e4},
       [](P& p) -> double& { return p.tire.updNumber("cornering_stiffness_N_per_rad"); }},
  };
  for (auto& f : h)
    if (f.param.symbol.empty()) f.param.symbol = f.param.name;
  return h;
}

QuarterCarDesign::QuarterCarDesign(const QuarterCarParams& nominal)
    : DesignModel(paramsOf(quarterCarHandles(), nominal.spring_free_length_from_ride_height
                                                   ? nominal.withRideHeightSpring()
                                                   : nominal)),
      nominal_(nominal.spring_free_length_from_ride_height ? nominal.withRideHeightSpring() : nominal),
      handles_(quarterCarHandles()) {
  nominal_.validate();
}

std::shared_ptr<QuarterCarDesign> QuarterCarDesign::fromFile(const std::string& path) {
  return std::make_shared<QuarterCarDesign>(QuarterCarParams::fromFile(path));
}

QuarterCarParams QuarterCarDesign::paramsFor(const std::vector<double>& b) const {
  QuarterCarParams p = nominal_;
  for (std::size_t i = 0; i < handles_.size(); ++i) handles_[i].field(p) = b[i];
  p.validate();
  return p;
}

namespace {
class QuarterCarInstance : public DesignInstance {
 public:
  explicit QuarterCarInstance(const QuarterCarParams& p) : car_(p) {}
  Scene& updScene() override { return car_.updScene(); }
  const Scene& getScene() const override { return car_.getScene(); }
  SimTK::State makeInitialState() const override { return car_.makeInitialState(true); }

 private:
  QuarterCar car_;
};

}  // namespace

std::unique_ptr<DesignInstance> QuarterCarDesign::DoBuild(const std::vector<double>& b) const {
  return std::make_unique<QuarterCarInstance>(paramsFor(b));
}

}  // namespace vdyn
