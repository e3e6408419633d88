#include "vdyn/tire/road.h"

#include <cmath>

namespace vdyn {

FlatRoad::FlatRoad(double h) : h_(requireFinite(h, "road height_m")) {}

SineRoad::SineRoad(double a, double f, double phase, double base, double start)
    : a_(requireNonNegative(a, "road amplitude_m")),
      w_(2 * SimTK::Pi * requireNonNegative(f, "road frequency_Hz")),
      phase_(requireFinite(phase, "road phase_rad")),
      base_(requireFinite(base, "road height_m")),
      start_(requireFinite(start, "road start_time_s")) {}

double SineRoad::DoHeight(double, double, double t) const {
  return t <= start_ ? base_ : base_ + a_ * std::sin(w_ * (t - start_) + phase_);
}
double SineRoad::DoHeightRate(double, double, double t) const {
  return t <= start_ ? 0.0 : a_ * w_ * std::cos(w_ * (t - start_) + phase_);
}

RoadParams RoadParams::fromParams(const ParamReader& r) {
  RoadParams p;
  p.type = r.string("type");
  p.height_m = r.numberOr("height_m", 0.0);
  if (p.type == "sine") {
    p.amplitude_m = r.number("amplitude_m");
    p.frequency_Hz = r.number("frequency_Hz");
    p.phase_rad = r.numberOr("phase_rad", 0.0);
    p.start_time_s = r.numberOr("start_time_s", 0.0);
  } else if (p.type != "flat") {
    throw Error(r.at("type") + ": unknown road type '" + p.type + "'; known: flat, sine");
  }
  r.requireAllKeysRead();
  makeRoad(p);  // validates the values
  return p;
}

std::shared_ptr<const Road> makeRoad(const RoadParams& p) {
  if (p.type == "flat") return std::make_shared<FlatRoad>(p.height_m);
  if (p.type == "sine") return std::make_shared<SineRoad>(p.amplitude_m, p.frequency_Hz, p.phase_rad, p.height_m, p.start_time_s);
  throw Error("unknown road type '" + p.type + "'; known: flat, sine");
}

}  // namespace vdyn
