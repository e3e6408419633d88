#include "vdyn/core/recorder.h"

#include <cstdio>
#include "vdyn/core/file_io.h"

namespace vdyn {

Recorder::Recorder(const Scene& scene, std::vector<std::string> names, SampleObserver observer)
    : scene_(scene), names_(std::move(names)), observer_(std::move(observer)) {
  for (const auto& n : names_) {
    outputs_.push_back(&scene_.getOutput(n));
    if (outputs_.back()->stage > stage_) stage_ = outputs_.back()->stage;
  }
  if (observer_ && stage_ < SimTK::Stage::Position) stage_ = SimTK::Stage::Position;  // it reads X_GB
  columns_.resize(names_.size());
}

void Recorder::syncWorkspace(const SimTK::State& like) {
  // Discrete variables (Instance stage and below) change the stage versions;
  // only then is a whole State copied.
  SimTK::Array_<SimTK::StageVersion> v;
  like.getSystemStageVersions(v);
  bool same = haveWork_ && v.size() == workVersions_.size();
  for (int k = 0; same && k <= SimTK::Stage::Instance && k < int(v.size()); ++k) same = v[k] == workVersions_[k];
  if (!same) {
    work_ = like;
    workVersions_ = v;
    haveWork_ = true;
  }
}

void Recorder::record(const SimTK::State& state) {
  const SimTK::State* s = &state;
  if (state.getSystemStage() < stage_) {
    syncWorkspace(state);
    work_.setTime(state.getTime());
    work_.updY() = state.getY();
    scene_.getSystem().realize(work_, stage_);
    s = &work_;
  }
  time_.push_back(s->getTime());
  for (std::size_t i = 0; i < outputs_.size(); ++i) columns_[i].push_back(outputs_[i]->eval(*s));
  if (observer_) observer_(*s);
}

void Recorder::recordInterpolated(double t, double t0, const SimTK::Vector& y0, const SimTK::Vector& f0,
                                  const SimTK::State& end) {
  const double t1 = end.getTime();
  assert(t0 < t1 && t0 <= t && t <= t1);
  syncWorkspace(end);
  const SimTK::Vector& y1 = end.getY();
  const SimTK::Vector& f1 = end.getYDot();
  // Simbody's IntegratorRep::interpolateOrder3 (cubic Hermite, error O(h^4)).
  const double h = t1 - t0, d = (t - t0) / h;
  const double cy1 = d * d * (3 - 2 * d), cy0 = 1 - cy1;
  const double hdd1 = h * d * (d - 1), cf1 = hdd1 * d, cf0 = cf1 - hdd1;
  work_.setTime(t);
  SimTK::Vector& y = work_.updY();
  for (int i = 0; i < y.size(); ++i) y[i] = cy0 * y0[i] + cy1 * y1[i] + cf0 * f0[i] + cf1 * f1[i];
  recordWorkspace();
}

void Recorder::recordAt(double t, const SimTK::Vector& y, const SimTK::State& like) {
  syncWorkspace(like);
  work_.setTime(t);
  work_.updY() = y;
  recordWorkspace();
}

void Recorder::recordWorkspace() {
  const double t = work_.getTime();
  const SimTK::System& system = scene_.getSystem();
  system.realize(work_, SimTK::Stage::Time);
  system.prescribeQ(work_);
  system.realize(work_, SimTK::Stage::Position);
  system.prescribeU(work_);
  if (stage_ > SimTK::Stage::Position) system.realize(work_, stage_);
  time_.push_back(t);
  for (std::size_t i = 0; i < outputs_.size(); ++i) columns_[i].push_back(outputs_[i]->eval(work_));
  if (observer_) observer_(work_);
}

const std::vector<double>& Recorder::column(const std::string& name) const {
  for (std::size_t i = 0; i < names_.size(); ++i)
    if (names_[i] == name) return columns_[i];
  throw Error("recorder has no column '" + name + "'");
}

void Recorder::writeCsv(const std::string& path) const {
  // Built in memory and written atomically: the CSV is complete or absent.
  std::string out = "t_s";
  for (const auto& n : names_) out += ',' + n;
  out += '\n';
  out.reserve(out.size() + time_.size() * (12 + 20 * columns_.size()));
  char buf[32];
  for (std::size_t r = 0; r < time_.size(); ++r) {
    std::snprintf(buf, sizeof buf, "%.9g", time_[r]);
    out += buf;
    for (const auto& c : columns_) {
      std::snprintf(buf, sizeof buf, ",%.12g", c[r]);
      out += buf;
    }
    out += '\n';
  }
  writeFileAtomic(path, out);
}

void Recorder::clear() {
  time_.clear();
  for (auto& c : columns_) c.clear();
}

}  // namespace vdyn
