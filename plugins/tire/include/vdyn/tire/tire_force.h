#pragma once
// The tire as a Simbody force element on a wheel body, and its plugin.
#include <functional>
#include <memory>
#include <optional>
#include <string>

#include <Simbody.h>

#include "vdyn/core/registry.h"
#include "vdyn/core/scene.h"
#include "vdyn/tire/road.h"
#include "vdyn/tire/tire_model.h"

namespace vdyn {

/// Contact geometry, kinematics and forces of one tire at one state.
struct TireContact {
  bool in_contact = false;
  SimTK::Vec3 p_GC;          ///< contact point on the road, in G, m
  SimTK::Rotation R_GC;      ///< contact frame C (x heading, y lateral, z normal) in G
  ContactKinematics kinematics;
  TireForces forces;         ///< in C, acting on the wheel
};

/// Force::Custom implementation: wheel W (spin axis `spinAxis_W` through the
/// origin), a torus of radii R1, R2 centred at `centre_W` on the spin axis
/// (the origin by default; an offset puts two tires on one axle body), against
/// the road height field. The slip velocities are those of `slipCentre_W` (by
/// default the tire centre): two tires of a bicycle's axle take the slip of the
/// axle centre, as the single wheel they stand for would, and carry only their
/// own normal loads (and so the roll moment) apart.
class TireForceImpl : public SimTK::Force::Custom::Implementation {
 public:
  TireForceImpl(const SimTK::MobilizedBody& wheel, std::shared_ptr<const TireModel> model,
                std::shared_ptr<const Road> road, const SimTK::UnitVec3& spinAxis_W,
                const SimTK::Vec3& centre_W = SimTK::Vec3(0));
  TireForceImpl(const SimTK::MobilizedBody& wheel, std::shared_ptr<const TireModel> model,
                std::shared_ptr<const Road> road, const SimTK::UnitVec3& spinAxis_W, const SimTK::Vec3& centre_W,
                const SimTK::Vec3& slipCentre_W);

  /// A tire with relaxation lengths keeps its two contact-patch deflections
  /// u_x, u_y (m) as continuous states (z) of `stateSubsystem` (the scene's
  /// force subsystem); call before the system's topology is realized.
  void setStateSubsystem(const SimTK::Subsystem& stateSubsystem) { zSub_ = &stateSubsystem; }
  bool hasRelaxationStates() const { return model_->hasRelaxation(); }

  /// Needs Stage::Velocity (and Time) realized.
  TireContact calcContact(const SimTK::State& state) const;
  /// Sets the patch deflections to the steady-state slip of the current
  /// velocities (u = sigma * slip), so a run starts without a transient in the
  /// tire; a no-op without relaxation. Needs Stage::Velocity realized.
  void initializeRelaxationStates(SimTK::State& state) const;
  /// d(u_x, u_y)/dt at this state (zero where the relaxation length is 0).
  SimTK::Vec2 calcRelaxationRates(const SimTK::State& state) const;

  void realizeTopology(SimTK::State& state) const override;
  void realizeDynamics(const SimTK::State& state) const override;  // z rates (a Dynamics-stage quantity)

  void calcForce(const SimTK::State& state, SimTK::Vector_<SimTK::SpatialVec>& bodyForces,
                 SimTK::Vector_<SimTK::Vec3>& particleForces, SimTK::Vector& mobilityForces) const override;
  /// Elastic energy of the radial spring (so Simbody's calcEnergy conserves).
  SimTK::Real calcPotentialEnergy(const SimTK::State& state) const override;

  const TireModel& getModel() const { return *model_; }

 private:
  struct Geometry {
    bool in_contact = false;
    SimTK::Vec3 p_GC{0};
    SimTK::Rotation R_GC{};
    double deflection = 0, camber = 0;
  };
  /// Geometry only (Stage::Position): contact point, frame, deflection.
  Geometry calcGeometry(const SimTK::State& s) const;
  /// Kinematics without the transient slips (Stage::Velocity).
  TireContact calcContactKinematics(const SimTK::State& s) const;

  SimTK::MobilizedBody wheel_;
  std::shared_ptr<const TireModel> model_;
  std::shared_ptr<const Road> road_;
  SimTK::UnitVec3 spinAxis_W_;
  SimTK::Vec3 centre_W_, slipCentre_W_;
  const SimTK::Subsystem* zSub_ = nullptr;
  mutable SimTK::ZIndex z0_;  // u_x at z0_, u_y at z0_ + 1 (set in realizeTopology)
};

/// Tire plugin: attaches a TireModel to a named wheel body of the scene, on the
/// scene's "road" service. Outputs (per instance name N): N.Fx_N, N.Fy_N, N.Fz_N,
/// N.Mz_N_m, N.deflection_m, N.slip_ratio, N.slip_angle_rad. With relaxation
/// lengths the tire carries two continuous states (patch deflections, m).
class TirePlugin : public ForceElementPlugin {
 public:
  TirePlugin(std::string type, std::string name, std::string wheelBody,
             std::shared_ptr<const TireModel> model,
             SimTK::UnitVec3 spinAxis_W = SimTK::UnitVec3(SimTK::YAxis),
             std::string roadService = "road", SimTK::Vec3 centre_W = SimTK::Vec3(0));
  /// Slip velocities taken at `slipCentre_W` instead of the tire centre.
  TirePlugin& setSlipCentre(const SimTK::Vec3& slipCentre_W);

  /// Valid after the plugin was added to a scene.
  const TireForceImpl& getForceElement() const;
  TireContact calcContact(const SimTK::State& s) const { return getForceElement().calcContact(s); }
  const std::string& wheelBody() const { return wheelBody_; }
  /// The tire law (valid from construction).
  const TireModel& getModel() const { return *model_; }

 protected:
  void DoAddTo(Scene& scene) override;

 private:
  std::string wheelBody_;
  std::shared_ptr<const TireModel> model_;
  SimTK::UnitVec3 spinAxis_W_;
  std::string roadService_;
  SimTK::Vec3 centre_W_;
  std::optional<SimTK::Vec3> slipCentre_W_;
  const TireForceImpl* impl_ = nullptr;  // owned by the Simbody force subsystem
};

/// A vehicle's tire: a tire plugin kind (built in, or from a plugin library)
/// and the "params" its plugin entry takes (that kind's keys: `vdyn list KIND`).
/// The vehicle does not read the params itself: the kind's factory does, when
/// the vehicle adds the tire, and names `where` in its errors.
struct TireChoice {
  std::string plugin = "gim";
  Json params = Json::object();
  std::string where = "tire";  ///< the data-file location of the tire block, for messages

  /// Reads a data file's tire block {"plugin": KIND, "params": {...}} and, if
  /// given, a block `overrides` of the same form over it (a derived vehicle
  /// file's or a scene's "tire"): its plugin replaces the base's, and its
  /// params merge over the base's while the kind stays the same; another kind
  /// starts from its own defaults with the override's params (the base's keys
  /// are the base kind's: gim's mu_max is not a key of linear). Unknown keys of
  /// either block are an error. (A scene's "overrides" patch the vehicle file
  /// itself before this: on the file that holds the block, a kind change
  /// removes the other kind's keys with null, as a JSON merge patch does.)
  static TireChoice fromParams(const ParamReader& base, const ParamReader* overrides = nullptr);
  /// The "linear" tire with this brush tire's (gim, fiala) vertical, slip and
  /// small-slip stiffnesses (LinearTireParams::linearised).
  TireChoice linearised() const;
  /// A number of `params`, for design parameters that vary it; the key must be
  /// given in the data (a kind's default is not known here). Stored as a double.
  double& updNumber(const std::string& key);
  /// A number of `params`, or a built-in kind's default for it; throws Error
  /// naming the key when neither is.
  double getNumber(const std::string& key) const;
  /// The plugin entry of this tire on wheel body `wheel`, for the registry;
  /// `entry` adds the entry's other keys (centre_m, slip_centre_m, ...).
  PluginSpec makeSpec(const std::string& name, const std::string& wheel, const Json& entry = Json::object()) const;
};

/// The static radial deflection of `model` under normal load fz_N (Fz = Kz delta), m.
double calcStaticDeflection(const TireModel& model, double fz_N);

/// A tire on its own in steady state (`vdyn tire`, the Python module's
/// vdyn.tire): the tire of a tire data file as a vehicle would add it.
struct SteadyTire {
  std::string kind;                 ///< the tire plugin kind (gim, fiala, linear, magic_formula, ...)
  std::unique_ptr<Plugin> plugin;   ///< owns the law
  const TireModel* model = nullptr; ///< the plugin's law

  /// `data`: a .tir property file (kind magic_formula) or a JSON file with a
  /// "tire" block {"plugin": KIND, "params": {...}} (a vehicle data file);
  /// the kind's factory in `registry` reads the params. Error names the file.
  static SteadyTire fromData(const std::string& data, const PluginRegistry& registry);

  /// Forces and moments at normal load fz_N (> 0), slip angle alpha_rad, slip
  /// ratio kappa, camber gamma_rad and forward speed vx_m_s (> 0): the
  /// deflection carries the load on the radial spring (calcStaticDeflection),
  /// Vy = vx tan(alpha), the wheel spins at vx (1 + kappa) / Re;
  /// kappa = (Omega Re - Vx) / |Vx| > 0 driving, alpha > 0 with the patch
  /// sliding to +y_C, so Fy < 0 there (tire_model.h). No relaxation states.
  TireForces calcForces(double fz_N, double alpha_rad, double kappa, double gamma_rad, double vx_m_s) const;
};

namespace detail {
/// The keys of a tire plugin entry: where the tire sits, and its kind's params P.
template <class P>
struct TireSpec {
  std::string wheel;
  SimTK::Vec3 spin_axis{0, 1, 0};
  SimTK::Vec3 centre_m{0, 0, 0};
  bool has_slip_centre = false;
  SimTK::Vec3 slip_centre_m{0, 0, 0};
  std::string side;
  P params;
};
template <class P>
const FieldTable<TireSpec<P>>& tireSpecFields() {
  using S = TireSpec<P>;
  static const auto t =
      FieldTable<S>()
          .custom("wheel", "-", "required", "wheel body (bindable: attach a corner)",
                  [](const ParamReader& r, S& s) { if (r.has("wheel")) s.wheel = r.string("wheel"); })
          .sample("\"wheel\"")
          .vec3("spin_axis", &S::spin_axis, "-", "spin axis in the wheel frame")
          .vec3("centre_m", &S::centre_m, "m", "tire centre on the wheel's spin axis, wheel frame")
          .custom("slip_centre_m", "m", "centre_m", "where slip velocities are taken, wheel frame",
                  [](const ParamReader& r, S& s) {
                    s.has_slip_centre = r.has("slip_centre_m");
                    if (s.has_slip_centre) s.slip_centre_m = r.vec3("slip_centre_m");
                  })
          .sample("[0, 0, 0]")
          .custom("side", "-", "\"\"", "left | right: the vehicle side of the wheel (a handed law mirrors; set by the vehicle)",
                  [](const ParamReader& r, S& s) {
                    s.side = r.stringOr("side", "");
                    if (!s.side.empty() && s.side != "left" && s.side != "right")
                      throw Error(r.at("side") + ": expected left or right, got '" + s.side + "'");
                  })
          .sample("\"left\"")
          .object("params", &S::params, P::fields(), "tire parameters (the keys 'params: ...')");
  return t;
}
}  // namespace detail

/// Registers tire kind `type` as a force-element plugin: its entry takes the
/// keys every tire has (wheel, spin_axis, centre_m, slip_centre_m, side) and
/// "params" read through P's field table (P::fields(), P::validate(where));
/// `makeModel` builds the law from them for a wheel on `side`.
template <class P>
void registerTireKind(PluginRegistry& registry, const std::string& type, const std::string& summary,
                      std::function<std::shared_ptr<const TireModel>(const P&, WheelSide)> makeModel) {
  registry.add(
      PluginKind::ForceElement, type,
      [type, makeModel](const PluginSpec& spec) -> std::unique_ptr<Plugin> {
        const detail::TireSpec<P> s = detail::tireSpecFields<P>().read(spec.params);
        if (spec.params.has("params")) {
          const ParamReader p = spec.params.child("params");
          p.requireAllKeysRead();  // an unknown tire key is an error, with the nearest key as a hint
          s.params.validate(p.where());
        }
        const WheelSide side = s.side == "left" ? WheelSide::Left : s.side == "right" ? WheelSide::Right : WheelSide::Unknown;
        auto plugin = std::make_unique<TirePlugin>(type, spec.name, spec.bound("wheel"), makeModel(s.params, side),
                                                   SimTK::UnitVec3(s.spin_axis), "road", s.centre_m);
        if (s.has_slip_centre) plugin->setSlipCentre(s.slip_centre_m);
        return plugin;
      },
      typeInfo(summary + "; outputs <name>.Fx_N, Fy_N, Fz_N, Mz_N_m, slip_ratio, slip_angle_rad",
               detail::tireSpecFields<P>()));
}

/// Registers the tire plugins "gim", "fiala" (BrushTireParams) and "linear"
/// (LinearTireParams). Parameters:
/// {"wheel": "<body name>", "params": {the kind's keys}, "spin_axis": [0, 1, 0],
///  "centre_m": [0, 0, 0] (tire centre on the wheel body's spin axis, m),
///  "slip_centre_m": [0, 0, 0] (where the slip velocities are taken; default the centre)}.
void registerTirePlugins(PluginRegistry& registry);

}  // namespace vdyn
