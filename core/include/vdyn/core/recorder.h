#pragma once
// Samples chosen scene outputs at report times. The simulation loop hands it the
// integrator's interpolant (recordInterpolated) or its interpolated states, so
// reporting never forces an integrator step, copies no State per sample and
// projects nothing.
#include <functional>
#include <string>
#include <vector>

#include "vdyn/core/scene.h"

namespace vdyn {

/// Called with each sample's state, realized through Stage::Position (an
/// animation's recorder, vdyn/core/animation.h).
using SampleObserver = std::function<void(const SimTK::State&)>;

class Recorder {
 public:
  /// Records time plus the named outputs (each must exist in the scene), and
  /// hands each sample's state to `observer` if one is given (the state is
  /// then realized through Stage::Position at least).
  Recorder(const Scene& scene, std::vector<std::string> outputNames, SampleObserver observer = {});

  /// Evaluates the outputs on `state`. If `state` is not realized far enough (the
  /// integrator's state is const), its t, q, u, z are copied into a workspace
  /// state that is realized instead (a full State copy would also copy and
  /// reallocate every cache entry).
  void record(const SimTK::State& state);

  /// Evaluates the outputs at time `t_s` on the cubic Hermite interpolant of
  /// one integrator step, from (t0_s, y0, ydot0) to the realized end state
  /// `end` (its Y and YDot; the formula of Simbody's interpolateOrder3, so the
  /// values are those of the integrator's own interpolated states, less the
  /// projection). Nothing is copied but the Y vector into one reused
  /// workspace state (a full State copy only when `end`'s discrete variables
  /// changed); the interpolated state is realized to the outputs' stage and
  /// not projected. t0_s < t_s <= end.getTime().
  void recordInterpolated(double t_s, double t0_s, const SimTK::Vector& y0, const SimTK::Vector& ydot0,
                          const SimTK::State& end);
  /// Evaluates the outputs at time `t_s` on y = `y` (an integrator's own
  /// interpolant's value there, CpodesStepper::interpolate) with the
  /// discrete part of `like` (a state of the same run), in the same reused
  /// workspace as recordInterpolated; realized to the outputs' stage, not projected.
  void recordAt(double t_s, const SimTK::Vector& y, const SimTK::State& like);

  const std::vector<std::string>& names() const { return names_; }
  std::size_t size() const { return time_.size(); }
  const std::vector<double>& time() const { return time_; }
  /// Column of one output; throws Error if it was not recorded.
  const std::vector<double>& column(const std::string& name) const;
  /// CSV with header "t_s,<name>[_unit]..." (output names carry their unit).
  void writeCsv(const std::string& path) const;
  void clear();

 private:
  const Scene& scene_;
  std::vector<std::string> names_;
  std::vector<const Output*> outputs_;
  SimTK::Stage stage_ = SimTK::Stage::Time;
  SampleObserver observer_;
  /// The workspace's discrete part is that of `like` (copies it if not).
  void syncWorkspace(const SimTK::State& like);
  /// Realizes the workspace (its t and y set) and records it.
  void recordWorkspace();
  SimTK::State work_;
  bool haveWork_ = false;
  SimTK::Array_<SimTK::StageVersion> workVersions_;  ///< of the state work_ was copied from
  std::vector<double> time_;
  std::vector<std::vector<double>> columns_;
};

}  // namespace vdyn
