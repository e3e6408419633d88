#include "vdyn/core/recorder.h"

#include <cstdio>
#include "vdyn/core/file_io.h"

namespace vdyn {

Recorder::Recorder(const Scene& scene, std::vector<std::string> names)
    : scene_(scene), names_(std::move(names)) {
  for (const auto& n : names_) {
    outputs_.push_back(&scene_.getOutput(n));
    if (outputs_.back()->stage > stage_) stage_ = outputs_.back()->stage;
  }
  columns_.resize(names_.size());
}

void Recorder::record(const SimTK::State& state) {
  const SimTK::State* s = &state;
  if (state.getSystemStage() < stage_) {
    if (!haveWork_) {
      work_ = state;
      haveWork_ = true;
    } else {
      work_.setTime(state.getTime());
      work_.updQ() = state.getQ();
      work_.updU() = state.getU();
      work_.updZ() = state.getZ();
    }
    scene_.getSystem().realize(work_, stage_);
    s = &work_;
  }
  time_.push_back(s->getTime());
  for (std::size_t i = 0; i < outputs_.size(); ++i) columns_[i].push_back(outputs_[i]->eval(*s));
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
