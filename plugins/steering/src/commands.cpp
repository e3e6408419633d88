// The waveform steering commands (vdyn/steering/commands.h).
#include "vdyn/steering/commands.h"

#include <algorithm>
#include <cmath>
#include <fstream>
#include <sstream>

#include "vdyn/steering/steering.h"

namespace vdyn {

namespace {

const double kTwoPi = 2 * SimTK::Pi;
const double kMaxAngle = SimTK::Pi / 4;  // +-45 deg: beyond it, a degree typed as radians

/// The cubic smoothstep h(u) = 3u^2 - 2u^3 on [0, 1] and its derivatives in u.
struct Smooth {
  double h, dh, ddh;
};
Smooth smoothstep(double u) { return {u * u * (3 - 2 * u), 6 * u * (1 - u), 6 - 12 * u}; }

void requireAngle(double a, const std::string& what) {
  if (!(std::abs(a) <= kMaxAngle))
    throw Error(what + " must lie in [-0.785398, 0.785398] rad (+-45 deg), got " + formatValue(a));
}

// --- ramp ---------------------------------------------------------------------
struct RampKeys {
  double initial_rad = 0, final_rad = 0, rate_rad_s = 0, start_time_s = 0, blend_s = 0.05;
};
const FieldTable<RampKeys>& rampFields() {
  using K = RampKeys;
  static const auto t =
      FieldTable<K>()
          .number("initial_rad", &K::initial_rad, "rad", "angle before the ramp, + left")
          .number("final_rad", &K::final_rad, "rad", "angle the ramp ends at and holds, + left", true)
          .sample("0.05")
          .number("rate_rad_s", &K::rate_rad_s, "rad/s", "steering rate of the ramp (its sign: final - initial's)", true)
          .sample("0.1")
          .number("start_time_s", &K::start_time_s, "s", "start of the ramp")
          .number("blend_s", &K::blend_s, "s",
                  "time over which the rate rises to rate_rad_s and falls back to 0 (cubic smoothstep; > 0, at most "
                  "(final - initial) / rate)");
  return t;
}
class RampCommand : public SteeringCommand {
 public:
  RampCommand(const RampKeys& k, const ParamReader& r) : k_(k) {
    requireAngle(k.initial_rad, r.at("initial_rad"));
    requireAngle(k.final_rad, r.at("final_rad"));
    requirePositive(k.blend_s, r.at("blend_s"));
    const double d = k.final_rad - k.initial_rad;
    if (!(k.rate_rad_s * d > 0))
      throw Error(r.at("rate_rad_s") + " = " + formatValue(k.rate_rad_s) + " must be non-zero with the sign of " +
                  "final_rad - initial_rad (" + formatValue(d) + ")");
    T_ = d / k.rate_rad_s + k.blend_s;  // the ramp's duration: its blends lose b/2 each
    if (!(T_ >= 2 * k.blend_s))
      throw Error(r.at("blend_s") + " = " + formatValue(k.blend_s) + " s must be at most (final_rad - initial_rad) / " +
                  "rate_rad_s = " + formatValue(d / k.rate_rad_s) + " s");
  }

 protected:
  SteerCommandValue DoCalc(double t) const override {
    const double tau = t - k_.start_time_s, b = k_.blend_s, R = k_.rate_rad_s, d = k_.final_rad - k_.initial_rad;
    if (tau <= 0) return {k_.initial_rad, 0, 0};
    if (tau >= T_) return {k_.final_rad, 0, 0};
    if (tau < b) {  // rate R h(u): angle R b (u^3 - u^4/2)
      const double u = tau / b;
      const Smooth s = smoothstep(u);
      return {k_.initial_rad + R * b * (u * u * u - 0.5 * u * u * u * u), R * s.h, R * s.dh / b};
    }
    if (tau > T_ - b) {
      const double v = (T_ - tau) / b;
      const Smooth s = smoothstep(v);
      return {k_.initial_rad + d - R * b * (v * v * v - 0.5 * v * v * v * v), R * s.h, -R * s.dh / b};
    }
    return {k_.initial_rad + R * (tau - 0.5 * b), R, 0};
  }

 private:
  RampKeys k_;
  double T_ = 0;
};

// --- sine and chirp: offset + A e(tau) sin(phi(tau)) ----------------------------
/// A sine of phase phi(tau) = 2 pi (f0 tau + (f1 - f0) tau^2 / (2 T)) over
/// [0, T], with the smoothstep envelope over `fade` at both ends.
class SweptSineCommand : public SteeringCommand {
 public:
  SweptSineCommand(double offset, double amplitude, double f0, double f1, double t0, double T, double fade)
      : c_(offset), A_(amplitude), f0_(f0), f1_(f1), t0_(t0), T_(T), fade_(fade) {}

 protected:
  std::vector<double> DoGetRateJumpTimes() const override {
    if (fade_ > 0) return {};
    return {t0_, t0_ + T_};  // the rate jumps by A w at both ends without a fade
  }
  SteerCommandValue DoCalc(double t) const override {
    const double tau = t - t0_;
    if (tau < 0 || tau >= T_) return {c_, 0, 0};  // from the right at both ends
    double e = 1, de = 0, dde = 0;
    if (fade_ > 0 && tau < fade_) {
      const Smooth s = smoothstep(tau / fade_);
      e = s.h, de = s.dh / fade_, dde = s.ddh / (fade_ * fade_);
    } else if (fade_ > 0 && tau > T_ - fade_) {
      const Smooth s = smoothstep((T_ - tau) / fade_);
      e = s.h, de = -s.dh / fade_, dde = s.ddh / (fade_ * fade_);
    }
    const double k = (f1_ - f0_) / T_;  // Hz/s
    const double phi = kTwoPi * (f0_ * tau + 0.5 * k * tau * tau), w = kTwoPi * (f0_ + k * tau), dw = kTwoPi * k;
    const double sn = std::sin(phi), cs = std::cos(phi);
    return {c_ + A_ * e * sn, A_ * (de * sn + e * cs * w),
            A_ * (dde * sn + 2 * de * cs * w + e * (cs * dw - sn * w * w))};
  }

 private:
  double c_, A_, f0_, f1_, t0_, T_, fade_;
};

struct SineKeys {
  double offset_rad = 0, amplitude_rad = 0, frequency_Hz = 0, start_time_s = 0, cycles = 1, fade_cycles = 0;
};
const FieldTable<SineKeys>& sineFields() {
  using K = SineKeys;
  static const auto t =
      FieldTable<K>()
          .number("offset_rad", &K::offset_rad, "rad", "angle about which it oscillates (and before and after), + left")
          .number("amplitude_rad", &K::amplitude_rad, "rad", "amplitude A (its sign: the first swing's)", true)
          .sample("0.02")
          .number("frequency_Hz", &K::frequency_Hz, "Hz", "frequency f", true)
          .number("start_time_s", &K::start_time_s, "s", "start t0 (phase 0)")
          .number("cycles", &K::cycles, "-", "periods of the sine (> 0; then offset_rad is held)")
          .number("fade_cycles", &K::fade_cycles, "-",
                  "periods over which the amplitude rises at the start and falls at the end (smoothstep; 0: none, "
                  "the rate jumps by 2 pi f A there)");
  return t;
}

struct ChirpKeys {
  double offset_rad = 0, amplitude_rad = 0, start_frequency_Hz = 0, end_frequency_Hz = 0, start_time_s = 0,
         duration_s = 0, fade_s = 0;
};
const FieldTable<ChirpKeys>& chirpFields() {
  using K = ChirpKeys;
  static const auto t =
      FieldTable<K>()
          .number("offset_rad", &K::offset_rad, "rad", "angle about which it oscillates, + left")
          .number("amplitude_rad", &K::amplitude_rad, "rad", "amplitude A", true)
          .sample("0.02")
          .number("start_frequency_Hz", &K::start_frequency_Hz, "Hz", "frequency f0 at the start", true)
          .number("end_frequency_Hz", &K::end_frequency_Hz, "Hz", "frequency f1 at the end (linear in time)", true)
          .number("start_time_s", &K::start_time_s, "s", "start t0")
          .number("duration_s", &K::duration_s, "s", "duration T of the sweep", true)
          .number("fade_s", &K::fade_s, "s", "time over which the amplitude rises and falls at the ends (0: none)");
  return t;
}

void checkOscillation(double offset, double A, const ParamReader& r, const char* amplitudeKey) {
  requireAngle(offset, r.at("offset_rad"));
  requireAngle(std::abs(offset) + std::abs(A), r.at(amplitudeKey) + " + |offset_rad|");
}

// --- sine with dwell (FMVSS 126) -------------------------------------------------
struct DwellKeys {
  double amplitude_rad = 0, frequency_Hz = 0.7, dwell_s = 0.5, start_time_s = 0;
};
const FieldTable<DwellKeys>& dwellFields() {
  using K = DwellKeys;
  static const auto t =
      FieldTable<K>()
          .number("amplitude_rad", &K::amplitude_rad, "rad", "amplitude A (its sign: the first swing's)", true)
          .sample("0.05")
          .number("frequency_Hz", &K::frequency_Hz, "Hz", "frequency of the sine (FMVSS 126: 0.7 Hz)")
          .number("dwell_s", &K::dwell_s, "s", "dwell at the second peak (FMVSS 126: 0.5 s)")
          .number("start_time_s", &K::start_time_s, "s", "start of the input");
  return t;
}
class SineWithDwellCommand : public SteeringCommand {
 public:
  SineWithDwellCommand(const DwellKeys& k, const ParamReader& r) : k_(k) {
    requireAngle(k.amplitude_rad, r.at("amplitude_rad"));
    requirePositive(k.frequency_Hz, r.at("frequency_Hz"));
    requireNonNegative(k.dwell_s, r.at("dwell_s"));
  }

 protected:
  /// The beginning and the completion of steer (the dwell's ends join at zero rate).
  std::vector<double> DoGetRateJumpTimes() const override {
    return {k_.start_time_s, k_.start_time_s + 1 / k_.frequency_Hz + k_.dwell_s};
  }
  SteerCommandValue DoCalc(double t) const override {
    const double w = kTwoPi * k_.frequency_Hz, A = k_.amplitude_rad, q3 = 0.75 / k_.frequency_Hz;
    double tau = t - k_.start_time_s;
    if (tau < 0 || tau >= 1 / k_.frequency_Hz + k_.dwell_s) return {0, 0, 0};  // from the right
    if (tau >= q3 && tau < q3 + k_.dwell_s) return {-A, 0, 0};  // sin at the third quarter: -1
    if (tau >= q3 + k_.dwell_s) tau -= k_.dwell_s;
    return {A * std::sin(w * tau), A * w * std::cos(w * tau), -A * w * w * std::sin(w * tau)};
  }

 private:
  DwellKeys k_;
};

// --- table (CSV) -------------------------------------------------------------------
struct TableKeys {
  std::string file, interpolation = "cubic";
};
const FieldTable<TableKeys>& tableFields() {
  using K = TableKeys;
  static const auto t =
      FieldTable<K>()
          .string("file", &K::file, "CSV file with columns time_s and angle_rad (relative: to the naming file)", true)
          .sample("\"inputs/ramp_and_hold.csv\"")
          .string("interpolation", &K::interpolation,
                  "cubic (a cubic spline with zero rate at the first and last rows: angle, rate, acceleration "
                  "continuous) | linear (rate piecewise constant, acceleration 0); outside the table the first / last "
                  "angle is held");
  return t;
}
class TableCommand : public SteeringCommand {
 public:
  TableCommand(const TableKeys& k, const ParamReader& r) : cubic_(k.interpolation == "cubic") {
    if (k.interpolation != "cubic" && k.interpolation != "linear")
      throw Error(r.at("interpolation") + ": must be cubic or linear, got '" + k.interpolation + "'");
    const std::string where = r.where();
    const std::string naming = where.substr(0, where.find(": "));
    const std::string path = resolveDataPath(k.file, naming);
    read(path);
    if (cubic_) spline();
  }

 protected:
  /// Linear: every row (the rate changes there); cubic: none (C2, zero rate at both ends).
  std::vector<double> DoGetRateJumpTimes() const override { return cubic_ ? std::vector<double>{} : t_; }
  SteerCommandValue DoCalc(double t) const override {
    const std::size_t n = t_.size();
    if (t <= t_.front()) return {y_.front(), 0, 0};
    if (t >= t_.back()) return {y_.back(), 0, 0};
    std::size_t i = std::upper_bound(t_.begin(), t_.end(), t) - t_.begin() - 1;
    if (i >= n - 1) i = n - 2;
    const double h = t_[i + 1] - t_[i];
    if (!cubic_) {
      const double s = (y_[i + 1] - y_[i]) / h;
      return {y_[i] + s * (t - t_[i]), s, 0};
    }
    const double a = (t_[i + 1] - t) / h, b = (t - t_[i]) / h;
    return {a * y_[i] + b * y_[i + 1] + ((a * a * a - a) * M_[i] + (b * b * b - b) * M_[i + 1]) * h * h / 6,
            (y_[i + 1] - y_[i]) / h + (-(3 * a * a - 1) * M_[i] + (3 * b * b - 1) * M_[i + 1]) * h / 6,
            a * M_[i] + b * M_[i + 1]};
  }

 private:
  void read(const std::string& path) {
    std::ifstream in(path);
    if (!in) throw Error(path + ": cannot open the steering table");
    std::string line;
    int ct = -1, ca = -1, lineNo = 0, ncols = 0;
    while (std::getline(in, line)) {
      ++lineNo;
      if (line.empty() || line[0] == '#') continue;
      std::vector<std::string> cells;
      std::stringstream ss(line);
      for (std::string c; std::getline(ss, c, ',');) {
        while (!c.empty() && (c.back() == '\r' || c.back() == ' ')) c.pop_back();
        while (!c.empty() && c.front() == ' ') c.erase(c.begin());
        cells.push_back(c);
      }
      if (ct < 0) {
        for (int j = 0; j < int(cells.size()); ++j) {
          if (cells[j] == "time_s") ct = j;
          if (cells[j] == "angle_rad") ca = j;
        }
        if (ct < 0 || ca < 0)
          throw Error(path + ":" + std::to_string(lineNo) + ": the header needs columns time_s and angle_rad, got '" +
                      line + "'");
        ncols = int(cells.size());
        continue;
      }
      if (int(cells.size()) != ncols)
        throw Error(path + ":" + std::to_string(lineNo) + ": " + std::to_string(cells.size()) + " cells, the header has " +
                    std::to_string(ncols));
      auto num = [&](int j, const char* name) {
        char* end = nullptr;
        const double v = std::strtod(cells[j].c_str(), &end);
        if (cells[j].empty() || *end != '\0' || !std::isfinite(v))
          throw Error(path + ":" + std::to_string(lineNo) + ": " + name + " '" + cells[j] + "' is not a finite number");
        return v;
      };
      const double t = num(ct, "time_s"), a = num(ca, "angle_rad");
      if (!t_.empty() && !(t > t_.back()))
        throw Error(path + ":" + std::to_string(lineNo) + ": time_s " + formatValue(t) +
                    " does not follow the previous " + formatValue(t_.back()) + " (times must increase)");
      requireAngle(a, path + ":" + std::to_string(lineNo) + ": angle_rad");
      t_.push_back(t);
      y_.push_back(a);
    }
    if (ct < 0) throw Error(path + ": empty steering table (a header time_s,angle_rad and at least 2 rows)");
    if (t_.size() < 2) throw Error(path + ": a steering table needs at least 2 rows, got " + std::to_string(t_.size()));
  }
  /// Second derivatives M of the clamped cubic spline with zero rate at the
  /// first and the last row (the manoeuvre starts and ends at rest, so the
  /// held values outside join with a continuous rate): the tridiagonal system
  /// by the Thomas algorithm.
  void spline() {
    const std::size_t n = t_.size();
    std::vector<double> a(n), b(n), c(n), r(n);
    for (std::size_t i = 0; i < n; ++i) {
      if (i == 0) {
        const double h = t_[1] - t_[0];
        a[i] = 0, b[i] = h / 3, c[i] = h / 6, r[i] = (y_[1] - y_[0]) / h;
      } else if (i + 1 == n) {
        const double h = t_[i] - t_[i - 1];
        a[i] = h / 6, b[i] = h / 3, c[i] = 0, r[i] = -(y_[i] - y_[i - 1]) / h;
      } else {
        const double h0 = t_[i] - t_[i - 1], h1 = t_[i + 1] - t_[i];
        a[i] = h0 / 6, b[i] = (h0 + h1) / 3, c[i] = h1 / 6;
        r[i] = (y_[i + 1] - y_[i]) / h1 - (y_[i] - y_[i - 1]) / h0;
      }
    }
    for (std::size_t i = 1; i < n; ++i) {  // forward elimination
      const double m = a[i] / b[i - 1];
      b[i] -= m * c[i - 1];
      r[i] -= m * r[i - 1];
    }
    M_.assign(n, 0.0);
    M_[n - 1] = r[n - 1] / b[n - 1];
    for (std::size_t i = n - 1; i-- > 0;) M_[i] = (r[i] - c[i] * M_[i + 1]) / b[i];
  }
  bool cubic_;
  std::vector<double> t_, y_, M_;
};

}  // namespace

void registerWaveformCommands(PluginRegistry& registry) {
  registry.addChoice<SteeringCommand>(
      "steering_command", "ramp",
      [](const ParamReader& r, const NoContext&) { return std::make_unique<RampCommand>(rampFields().read(r), r); },
      typeInfo("a ramp from initial_rad at rate_rad_s to final_rad, its rate blended in and out over blend_s",
               rampFields()));
  registry.addChoice<SteeringCommand>(
      "steering_command", "sine",
      [](const ParamReader& r, const NoContext&) {
        const SineKeys k = sineFields().read(r);
        checkOscillation(k.offset_rad, k.amplitude_rad, r, "amplitude_rad");
        requirePositive(k.frequency_Hz, r.at("frequency_Hz"));
        requirePositive(k.cycles, r.at("cycles"));
        requireNonNegative(k.fade_cycles, r.at("fade_cycles"));
        if (!(2 * k.fade_cycles <= k.cycles))
          throw Error(r.at("fade_cycles") + " = " + formatValue(k.fade_cycles) + " must be at most half of cycles (" +
                      formatValue(k.cycles) + ")");
        return std::make_unique<SweptSineCommand>(k.offset_rad, k.amplitude_rad, k.frequency_Hz, k.frequency_Hz,
                                                  k.start_time_s, k.cycles / k.frequency_Hz,
                                                  k.fade_cycles / k.frequency_Hz);
      },
      typeInfo("offset_rad + A sin(2 pi f (t - t0)) over `cycles` periods, optionally faded in and out", sineFields()));
  registry.addChoice<SteeringCommand>(
      "steering_command", "chirp",
      [](const ParamReader& r, const NoContext&) {
        const ChirpKeys k = chirpFields().read(r);
        checkOscillation(k.offset_rad, k.amplitude_rad, r, "amplitude_rad");
        requirePositive(k.start_frequency_Hz, r.at("start_frequency_Hz"));
        requirePositive(k.end_frequency_Hz, r.at("end_frequency_Hz"));
        requirePositive(k.duration_s, r.at("duration_s"));
        requireNonNegative(k.fade_s, r.at("fade_s"));
        if (!(2 * k.fade_s <= k.duration_s))
          throw Error(r.at("fade_s") + " = " + formatValue(k.fade_s) + " s must be at most half of duration_s (" +
                      formatValue(k.duration_s) + " s)");
        return std::make_unique<SweptSineCommand>(k.offset_rad, k.amplitude_rad, k.start_frequency_Hz,
                                                  k.end_frequency_Hz, k.start_time_s, k.duration_s, k.fade_s);
      },
      typeInfo("a sine whose frequency sweeps linearly from start_frequency_Hz to end_frequency_Hz over duration_s",
               chirpFields()));
  registry.addChoice<SteeringCommand>(
      "steering_command", "sine_with_dwell",
      [](const ParamReader& r, const NoContext&) {
        return std::make_unique<SineWithDwellCommand>(dwellFields().read(r), r);
      },
      typeInfo("FMVSS 126's sine with dwell: A sin(2 pi f t) to its second peak, held dwell_s, then back to 0",
               dwellFields()));
  registry.addChoice<SteeringCommand>(
      "steering_command", "table",
      [](const ParamReader& r, const NoContext&) { return std::make_unique<TableCommand>(tableFields().read(r), r); },
      typeInfo("a measured manoeuvre: time_s, angle_rad from a CSV file, cubic or linear interpolation",
               tableFields()));
}

}  // namespace vdyn
