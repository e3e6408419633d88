#pragma once
// Design parameters (the seed's b, chapter 4) as named handles into model data.
// A DesignModel is the constant model: the list of parameters with their
// nominal values and a builder that turns a design vector into a fresh scene.
// A DesignInstance is one built scene for one design (its data). Every
// sensitivity method works through this interface only, so a vehicle exposes
// its parameters once and every method (finite differences, mixed, reference)
// sees the same ones.
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "vdyn/core/scene.h"

namespace vdyn {

/// One design parameter b_i.
struct DesignParameter {
  /// Key path of the value in the model's data (ends in its unit), e.g.
  /// "corner.spring.stiffness_N_per_m"; the name studies and data files use.
  std::string name;
  /// The seed's symbol where it has one ("m1", "K", "s'"), else the name.
  std::string symbol;
  /// SI unit of the value ("kg", "N/m", "m").
  std::string unit;
  /// Nominal value, in `unit`.
  double nominal = 0;
  /// Typical magnitude, in `unit` (> 0): perturbations are relative to
  /// max(|nominal|, scale), so a parameter whose nominal value is 0 (s') still
  /// gets a meaningful perturbation.
  double scale = 1;
};

/// A scene built for one design vector, with the rule that makes its initial state.
class DesignInstance {
 public:
  virtual ~DesignInstance() = default;
  virtual Scene& updScene() = 0;
  virtual const Scene& getScene() const = 0;
  /// The initial state of this design (may depend on b, e.g. a static
  /// equilibrium). Called after the cost has been added to the scene.
  virtual SimTK::State makeInitialState() const = 0;
};

/// The model family b -> scene.
class DesignModel {
 public:
  virtual ~DesignModel() = default;

  /// Every parameter the model exposes, in a fixed order.
  const std::vector<DesignParameter>& getParameters() const { return params_; }
  std::vector<double> getNominalValues() const;
  /// Index of the parameter named `name` (its key path or its seed symbol);
  /// throws Error listing the known names if there is none.
  int findParameter(const std::string& name) const;
  /// Builds the scene for `values` (one per parameter, finite); throws Error
  /// naming the parameter and value otherwise.
  std::unique_ptr<DesignInstance> build(const std::vector<double>& values) const;
  /// A short name of the model for messages ("quarter car").
  virtual std::string describe() const = 0;

 protected:
  explicit DesignModel(std::vector<DesignParameter> params);
  virtual std::unique_ptr<DesignInstance> DoBuild(const std::vector<double>& values) const = 0;

 private:
  std::vector<DesignParameter> params_;
};

/// Helper for models whose data is a plain parameter struct P: each handle is a
/// DesignParameter plus an accessor to the field it stands for.
template <class P>
struct FieldHandle {
  DesignParameter param;
  std::function<double&(P&)> field;
};

}  // namespace vdyn
