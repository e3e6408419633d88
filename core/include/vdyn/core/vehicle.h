#pragma once
// The vehicle of a scene, as the scene machinery sees it: a builder registered
// by name (quarter_car, bicycle, fourws, ... in vehicles/) that owns a Scene,
// names its attachments (the bindings a plugin gets from "attach": "front_axle")
// and makes the initial state. Concrete vehicles keep their own richer C++ API;
// this interface is what a scene file can reach.
#include <map>
#include <memory>
#include <string>
#include <typeinfo>
#include <vector>

#include "vdyn/core/params.h"
#include "vdyn/core/scene.h"

namespace vdyn {

class PluginRegistry;

/// What a vehicle builder receives.
struct VehicleSpec {
  std::string type;                ///< registered builder name ("fourws", ...)
  ParamReader data;                ///< the vehicle data: data file with the scene's overrides merged over it
  const PluginRegistry* registry;  ///< where the vehicle looks up its own plugins (tires)
};

/// Bindings of one attachment: plugin key -> scene name, e.g. for an axle
/// {"chassis": "chassis", "knuckles": "rf.knuckle,lf.knuckle", "spin_axis": "0 1 0"}.
using Attachment = std::map<std::string, std::string>;

class Vehicle {
 public:
  virtual ~Vehicle() = default;
  Vehicle(const Vehicle&) = delete;
  Vehicle& operator=(const Vehicle&) = delete;

  const std::string& type() const { return type_; }
  Scene& updScene() { return DoUpdScene(); }
  const Scene& getScene() const { return const_cast<Vehicle*>(this)->DoUpdScene(); }

  /// Names of the attachments plugins can name ("chassis", "front_axle", "rf", ...).
  std::vector<std::string> getAttachmentNames() const;
  /// The bindings of one attachment; throws Error listing the known names.
  const Attachment& getAttachment(const std::string& name) const;

  /// The initial state: assembled, at rest or moving forward at `speed_m_s`
  /// (m/s, finite; a vehicle that cannot move throws unless it is 0).
  SimTK::State makeInitialState(double speed_m_s) const;
  /// Facts for a summary (total_mass_kg, dof, assembly_max_body_move_m, ...),
  /// on the state makeInitialState returned.
  Json describe(const SimTK::State& initial) const { return DoDescribe(initial); }
  /// Values the builder derived from a rule in its data (the quarter car's
  /// spring free length from the ride height), as a merge patch over the data
  /// that states them instead: a design study holds them at the nominal
  /// design's values (a datum) while it perturbs others. {} if none.
  Json derivedData() const { return DoGetDerivedData(); }

  /// The concrete vehicle behind this builder (WheeledVehicle for "fourws",
  /// Bicycle, QuarterCar), for code that needs its own C++ API on a vehicle a
  /// scene composed (e.g. ch3_work_precision maps the reduced model's state
  /// from the constrained one's): the scene stays the one composition. Throws
  /// Error naming the builder and V if the vehicle is not a V.
  template <class V>
  V& getConcrete() {
    if (auto* v = dynamic_cast<V*>(this)) return *v;
    if (void* p = DoGetConcrete(typeid(V))) return *static_cast<V*>(p);
    throwNotA(typeid(V));
  }
  template <class V>
  const V& getConcrete() const {
    return const_cast<Vehicle*>(this)->getConcrete<V>();
  }

 protected:
  explicit Vehicle(std::string type) : type_(std::move(type)) {}
  virtual Scene& DoUpdScene() = 0;
  virtual SimTK::State DoMakeInitialState(double speed_m_s) const = 0;
  virtual Json DoDescribe(const SimTK::State&) const { return Json::object(); }
  virtual Json DoGetDerivedData() const { return Json::object(); }
  /// The concrete object if it is of type `type` (a builder that wraps one
  /// returns its address for that type), else nullptr.
  virtual void* DoGetConcrete(const std::type_info& /*type*/) { return nullptr; }
  /// Builders fill this in their constructors.
  std::map<std::string, Attachment> attachments_;

 private:
  [[noreturn]] void throwNotA(const std::type_info& type) const;
  std::string type_;
};

}  // namespace vdyn
