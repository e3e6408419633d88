#pragma once
// An animation of a run (vdyn run --animation): every mobilized body of the
// scene drawn as a simple shape from its mass properties, its pose X_GB
// sampled at the run's report times, written as a glTF 2.0 binary (.glb) and
// a self-contained HTML viewer (three.js and the .glb inlined). Recording
// costs nothing unless asked: `vdyn run --animation` hands an analysis an
// AnimationRecorder (AnalysisContext::animation), and the analysis gives the
// recorder's observer() to the Recorder of the run it reports.
//
// The .glb: a root node "ground" turns Simbody's z-up ground frame G into
// glTF's y-up; under it one node per body (its TRS is X_GB: translation p_GB,
// m, rotation q_GB) and the plugins' decorations (a reference path as a line,
// cones). One animation "run": per body a translation and a rotation channel,
// LINEAR, keyed at the sample times (s). glTF accessors are float32, so the
// channels hold the poses to float precision (~6e-8 relative); the exact
// poses are in the binary buffer too, as float64, named by the asset's
// extras "vdyn" (bodies, sample count, bufferViews and layout): tests read
// those to 1e-9.
#include <string>
#include <vector>

#include <Simbody.h>

#include "vdyn/core/plugin.h"
#include "vdyn/core/recorder.h"

namespace vdyn {

class Scene;

/// How a body is drawn (in its body frame B, m).
struct AnimationShape {
  enum Kind { None, Box, Cylinder } kind = None;  ///< None: a massless body, not drawn
  SimTK::Vec3 centre_B{0};      ///< box or cylinder centre in B (the body's mass centre), m
  SimTK::Vec3 size_m{0};        ///< box: side lengths along B's x, y, z; cylinder: (radius, width along B's y, 0)
  SimTK::Vec3 colour{0.5};      ///< RGB in [0, 1]
};

class AnimationRecorder {
 public:
  /// One entry per mobilized body of `scene` but ground, in mobilized body
  /// index order; the shapes from each body's default mass properties: a body
  /// named "*wheel" (or a bicycle's "front_axle"/"rear_axle") is a cylinder about B's
  /// y (its spin axis) of radius sqrt(2 Iyy / m), others the box of the same
  /// central inertia, except a body with a spherical inertia (lumped data that
  /// says nothing of its shape, an arm's): a thin link between the farthest of
  /// its joints (mobilizer frames) and mass centre. The plugins' decorations
  /// are collected here.
  explicit AnimationRecorder(const Scene& scene) { restart(scene); }

  /// Starts afresh on `scene` (bodies, shapes and decorations read from it,
  /// no samples): an analysis that builds its own scene for the run it
  /// reports (ISO 3888-2 at its highest passing speed) records that one. The
  /// scene must outlive the recording's samples.
  void restart(const Scene& scene);

  /// Records X_GB of every body; `state` realized through Stage::Position.
  /// A sample at a time not after the last one starts the recording afresh
  /// (an analysis that runs the scene again: the animation shows its last run).
  void sample(const SimTK::State& state);

  /// The observer a Recorder calls at each sample: sample(state).
  SampleObserver observer() {
    return [this](const SimTK::State& state) { sample(state); };
  }

  std::size_t size() const { return time_s_.size(); }
  const std::vector<double>& time() const { return time_s_; }
  const std::vector<std::string>& bodyNames() const { return names_; }
  const std::vector<AnimationShape>& shapes() const { return shapes_; }
  /// X_GB of body b at sample k.
  const SimTK::Transform& pose(std::size_t k, std::size_t b) const { return poses_[k * names_.size() + b]; }
  const SceneDecorations& decorations() const { return decorations_; }
  /// An analysis adds what it shows besides the plugins' decorations (ISO
  /// 3888-2: its cones) after restart().
  SceneDecorations& updDecorations() { return decorations_; }

  /// The .glb file's bytes. Throws Error if nothing was recorded.
  std::string makeGlb() const;

 private:
  const SimTK::SimbodyMatterSubsystem* matter_ = nullptr;
  std::vector<SimTK::MobilizedBodyIndex> bodies_;
  std::vector<std::string> names_;
  std::vector<AnimationShape> shapes_;
  SceneDecorations decorations_;
  std::vector<double> time_s_;
  std::vector<SimTK::Transform> poses_;  ///< sample-major
};

/// The HTML viewer of `glb` (bytes of a .glb), with three.js (found by
/// findThreeJs) and the .glb inlined in base64: opens offline from a file.
/// A time slider and a play button; "#t=1.5" in the address shows t = 1.5 s.
std::string makeAnimationViewer(const std::string& glb, const std::string& title);

/// The folder with three.js's build (three.module.js, three.core.js): the
/// environment variable VDYN_THREE_DIR, else the build tree's copy (npm, at
/// build time), else <data folder>/viewer/three of an installed vdyn. Throws
/// Error naming every folder tried.
std::string findThreeJs();

/// Writes `<stem>.glb` and `<stem>.html` (writeFileAtomic); returns their paths.
std::vector<std::string> writeAnimation(const AnimationRecorder& recorder, const std::string& stem,
                                        const std::string& title);

}  // namespace vdyn
