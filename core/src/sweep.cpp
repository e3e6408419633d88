#include "vdyn/core/sweep.h"

#include "vdyn/core/interrupt.h"
#include "vdyn/core/key_path.h"
#include "vdyn/core/named_outcome.h"
#include "vdyn/core/scene_file.h"

#include <algorithm>
#include <cassert>
#include <cctype>
#include <cmath>
#include <atomic>
#include <chrono>
#include <cstdio>
#include <ctime>
#include <filesystem>
#include <fstream>
#include <map>
#include <mutex>
#include <set>
#include <sstream>
#include <thread>
#include <sys/resource.h>
#include <unistd.h>

namespace vdyn {

namespace {

std::string dumpCompact(const Json& j) { return j.dump(-1, ' ', false, Json::error_handler_t::replace); }

/// "file.json: a.b" + key -> "file.json: a.b.key" (ParamReader's convention).
std::string at(const std::string& where, const std::string& key) {
  if (!where.empty() && where.back() == ':') return where + " " + key;
  return where + "." + key;
}
std::string atIndex(const std::string& where, std::size_t i) { return where + "[" + std::to_string(i) + "]"; }

std::size_t editDistance(const std::string& a, const std::string& b) {
  std::vector<std::size_t> prev(b.size() + 1), cur(b.size() + 1);
  for (std::size_t j = 0; j <= b.size(); ++j) prev[j] = j;
  for (std::size_t i = 1; i <= a.size(); ++i) {
    cur[0] = i;
    for (std::size_t j = 1; j <= b.size(); ++j)
      cur[j] = std::min({prev[j] + 1, cur[j - 1] + 1, prev[j - 1] + (a[i - 1] == b[j - 1] ? 0 : 1)});
    std::swap(prev, cur);
  }
  return prev[b.size()];
}

/// Throws naming the first key of `obj` not in `allowed`, with the nearest allowed one.
void requireKnownKeys(const Json& obj, const std::vector<std::string>& allowed, const std::string& where) {
  for (auto it = obj.begin(); it != obj.end(); ++it) {
    if (std::find(allowed.begin(), allowed.end(), it.key()) != allowed.end()) continue;
    std::string best;
    std::size_t bestD = 1000;
    for (const auto& a : allowed) {
      const std::size_t dd = editDistance(it.key(), a);
      if (dd < bestD) bestD = dd, best = a;
    }
    std::string known;
    for (const auto& a : allowed) known += (known.empty() ? "" : ", ") + a;
    throw Error(at(where, it.key()) + ": unknown key" +
                (bestD <= 3 ? " (did you mean '" + best + "'?)" : "") + "; known: " + known);
  }
}

const Json& requireKey(const Json& obj, const std::string& key, const std::string& where) {
  auto it = obj.find(key);
  if (it == obj.end()) throw Error(at(where, key) + ": missing key");
  return *it;
}

const Json& requireObject(const Json& j, const std::string& where) {
  if (!j.is_object()) throw Error(where + ": expected an object, got " + dumpCompact(j));
  return j;
}

const Json& requireArray(const Json& j, const std::string& where, bool nonEmpty = true) {
  if (!j.is_array()) throw Error(where + ": expected an array, got " + dumpCompact(j));
  if (nonEmpty && j.empty()) throw Error(where + ": expected a non-empty array, got []");
  return j;
}

double requireNumber(const Json& j, const std::string& where) {
  if (!j.is_number()) throw Error(where + ": expected a number, got " + dumpCompact(j));
  return requireFinite(j.get<double>(), where);
}

long long requireCount(const Json& j, const std::string& where, long long max = kMaxSweepVariations) {
  if (!j.is_number_integer() || j.get<long long>() < 1 || j.get<long long>() > max)
    throw Error(where + ": expected an integer in [1, " + std::to_string(max) + "], got " + dumpCompact(j));
  return j.get<long long>();
}

/// Checks that `path` is a KeyPath (the error names `where` and the path).
void validatePath(const std::string& path, const std::string& where) { KeyPath::parse(path, where); }

std::uint64_t splitmix64(std::uint64_t& x) {
  std::uint64_t z = (x += 0x9e3779b97f4a7c15ULL);
  z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
  z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
  return z ^ (z >> 31);
}
std::uint64_t rotl(std::uint64_t x, int k) { return (x << k) | (x >> (64 - k)); }

std::uint64_t fnv1a(std::uint64_t h, const std::string& s) {
  for (unsigned char c : s) {
    h ^= c;
    h *= 0x100000001b3ULL;
  }
  h ^= 0xff;  // separator
  h *= 0x100000001b3ULL;
  return h;
}

double threadCpuSeconds() {
  timespec ts;
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
  return ts.tv_sec + 1e-9 * ts.tv_nsec;
}

std::string csvQuote(const std::string& s) {
  if (s.find_first_of(",\"\n\r") == std::string::npos) return s;
  std::string q = "\"";
  for (char c : s) {
    if (c == '"') q += '"';
    q += c;
  }
  return q + "\"";
}

}  // namespace

// --- random numbers ---------------------------------------------------------------
SweepRandom::SweepRandom(std::uint64_t seed) {
  std::uint64_t x = seed;
  for (auto& s : s_) s = splitmix64(x);
}

std::uint64_t SweepRandom::next() {
  const std::uint64_t result = rotl(s_[1] * 5, 7) * 9;
  const std::uint64_t t = s_[1] << 17;
  s_[2] ^= s_[0];
  s_[3] ^= s_[1];
  s_[1] ^= s_[2];
  s_[0] ^= s_[3];
  s_[2] ^= t;
  s_[3] = rotl(s_[3], 45);
  return result;
}

double SweepRandom::uniform() { return double(next() >> 11) * 0x1.0p-53; }

std::uint64_t SweepRandom::below(std::uint64_t n) {
  // Rejection of the top partial block: exact, and the same on every platform.
  const std::uint64_t limit = ~std::uint64_t(0) - (~std::uint64_t(0) % n);
  for (;;) {
    const std::uint64_t x = next();
    if (x < limit) return x % n;
  }
}

// --- variations -------------------------------------------------------------------
std::string Variation::id() const {
  std::string s;
  for (const auto& st : settings) s += (s.empty() ? "" : ";") + st.key + "=" + dumpCompact(st.value);
  return s;
}

const Json* Variation::find(const std::string& key) const {
  for (const auto& st : settings)
    if (st.key == key) return &st.value;
  return nullptr;
}

std::vector<std::vector<SweepSetting>> makeGridVariations(const std::vector<GridAxis>& axes) {
  std::vector<std::vector<SweepSetting>> out(1);
  for (const GridAxis& ax : axes) {
    std::vector<std::vector<SweepSetting>> next;
    for (const auto& base : out)
      for (const auto& vals : ax.values) {
        assert(vals.size() == ax.keys.size());
        auto v = base;
        for (std::size_t k = 0; k < ax.keys.size(); ++k) v.push_back({ax.keys[k], vals[k]});
        next.push_back(std::move(v));
      }
    out = std::move(next);
  }
  return out;
}

std::vector<std::vector<SweepSetting>> makeLatinHypercubeVariations(const std::vector<SampleRange>& ranges,
                                                                    int samples, std::uint64_t seed) {
  SweepRandom rng(seed);
  std::vector<std::vector<SweepSetting>> out(samples);
  for (const SampleRange& r : ranges) {
    std::vector<int> perm(samples);
    for (int i = 0; i < samples; ++i) perm[i] = i;
    for (int i = samples - 1; i > 0; --i) std::swap(perm[i], perm[rng.below(std::uint64_t(i) + 1)]);
    for (int i = 0; i < samples; ++i) {
      const double u = (perm[i] + rng.uniform()) / samples;
      out[i].push_back({r.key, r.min + (r.max - r.min) * u});
    }
  }
  return out;
}

std::vector<std::vector<SweepSetting>> makeMonteCarloVariations(const std::vector<SampleRange>& ranges,
                                                                int samples, std::uint64_t seed) {
  SweepRandom rng(seed);
  std::vector<std::vector<SweepSetting>> out(samples);
  for (int i = 0; i < samples; ++i)
    for (const SampleRange& r : ranges) out[i].push_back({r.key, r.min + (r.max - r.min) * rng.uniform()});
  return out;
}

void SweepDescription::addVariations(const std::vector<std::vector<SweepSetting>>& sets) {
  for (const auto& s : sets) {
    Variation v;
    v.index = variations.size();
    v.settings = s;
    for (const auto& st : s)
      if (std::find(keys.begin(), keys.end(), st.key) == keys.end()) keys.push_back(st.key);
    variations.push_back(std::move(v));
  }
}

std::uint64_t SweepDescription::fingerprint() const {
  std::uint64_t h = 0xcbf29ce484222325ULL;
  for (const auto& k : keys) h = fnv1a(h, k);
  for (const auto& c : collect) h = fnv1a(h, "collect:" + c);
  for (const auto& s : common) h = fnv1a(h, "set:" + s.key + "=" + dumpCompact(s.value));
  for (const auto& v : variations) h = fnv1a(h, v.id());
  return h;
}

// --- the sweep file -----------------------------------------------------------------
SweepDescription SweepDescription::fromFile(const std::string& path) {
  const Json j = readJsonFile(path);
  const std::filesystem::path p(path);
  SweepDescription d = fromJson(j, p.filename().string() + ":", p.has_parent_path() ? p.parent_path().string() : ".");
  d.file = path;
  if (d.name.empty()) {
    std::string stem = p.filename().string();
    for (const char* ext : {".json"}) {
      const std::string e(ext);
      if (stem.size() > e.size() && stem.compare(stem.size() - e.size(), e.size(), e) == 0)
        stem.resize(stem.size() - e.size());
    }
    if (stem.size() > 6 && stem.compare(stem.size() - 6, 6, ".sweep") == 0) stem.resize(stem.size() - 6);
    d.name = stem;
  }
  return d;
}

SweepDescription SweepDescription::fromJson(const Json& j, const std::string& where, const std::string& baseDir) {
  requireObject(j, where);
  requireKnownKeys(j, {"scene", "name", "set", "variations", "collect", "output", "plots"}, where);
  SweepDescription d;
  // Relative to the sweep file's folder when the file is there; else as
  // given (the scene loader then looks along the data search path).
  auto resolve = [&](const std::string& f, bool mustExist) {
    if (f.empty() || f[0] == '/' || baseDir.empty()) return f;
    const std::string local = baseDir + "/" + f;
    return !mustExist || std::filesystem::exists(local) ? local : f;
  };
  auto str = [&](const std::string& key) {
    const Json& v = requireKey(j, key, where);
    if (!v.is_string() || v.get<std::string>().empty())
      throw Error(at(where, key) + ": expected a non-empty string, got " + dumpCompact(v));
    return v.get<std::string>();
  };
  // The one path rule (docs/user_guide.md, "Scene files": "Files resolve where a reader expects them"):
  // relative to the naming file (this sweep file), then along the data path.
  d.scene = str("scene");
  if (!d.scene.empty() && d.scene[0] != '/' && !baseDir.empty()) {
    const std::string f = d.scene;
    std::string looked = baseDir;
    d.scene.clear();
    if (std::filesystem::is_regular_file(baseDir + "/" + f)) d.scene = baseDir + "/" + f;
    for (const auto& dir : dataSearchPath()) {
      if (!d.scene.empty()) break;
      if (std::filesystem::is_regular_file(dir + "/" + f)) d.scene = dir + "/" + f;
      looked += ", " + dir;
    }
    if (d.scene.empty()) throw Error(at(where, "scene") + ": scene file '" + f + "' not found (looked in " + looked + ")");
  }
  if (j.contains("name")) d.name = str("name");
  if (j.contains("output")) d.output = resolve(str("output"), false);
  if (j.contains("set")) {
    const std::string w = at(where, "set");
    for (auto it = requireObject(j["set"], w).begin(); it != j["set"].end(); ++it) {
      validatePath(it.key(), w);
      d.common.push_back({it.key(), it.value()});
    }
  }
  if (j.contains("collect")) {
    const std::string w = at(where, "collect");
    const Json& c = requireArray(j["collect"], w);
    for (std::size_t i = 0; i < c.size(); ++i) {
      if (!c[i].is_string()) throw Error(atIndex(w, i) + ": expected a summary path (string), got " + dumpCompact(c[i]));
      const std::string p = c[i].get<std::string>();
      validatePath(p, atIndex(w, i));
      if (std::find(d.collect.begin(), d.collect.end(), p) != d.collect.end())
        throw Error(atIndex(w, i) + ": '" + p + "' is collected twice");
      d.collect.push_back(p);
    }
  }

  const std::string wv = at(where, "variations");
  const Json& blocks = requireArray(requireKey(j, "variations", where), wv);
  for (std::size_t b = 0; b < blocks.size(); ++b) {
    const std::string wb = atIndex(wv, b);
    requireObject(blocks[b], wb);
    requireKnownKeys(blocks[b], {"grid", "list", "latin_hypercube", "monte_carlo"}, wb);
    if (blocks[b].size() != 1)
      throw Error(wb + ": expected exactly one of grid, list, latin_hypercube, monte_carlo, got " +
                  dumpCompact(blocks[b]));
    const std::string kind = blocks[b].begin().key();
    const Json& body = blocks[b].begin().value();
    const std::string wk = at(wb, kind);
    std::vector<std::vector<SweepSetting>> sets;
    std::set<std::string> blockKeys;
    auto newKey = [&](const std::string& key, const std::string& w) {
      validatePath(key, w);
      if (!blockKeys.insert(key).second) throw Error(w + ": key '" + key + "' is varied twice in this block");
    };
    if (kind == "grid") {
      std::vector<GridAxis> axes;
      const Json& ax = requireArray(body, wk);
      for (std::size_t a = 0; a < ax.size(); ++a) {
        const std::string wa = atIndex(wk, a);
        requireObject(ax[a], wa);
        requireKnownKeys(ax[a], {"key", "keys", "values", "from", "to", "count"}, wa);
        GridAxis g;
        if (ax[a].contains("key") == ax[a].contains("keys"))
          throw Error(wa + ": expected one of 'key' (a path) or 'keys' (paths changed together), got " +
                      dumpCompact(ax[a]));
        if (ax[a].contains("key")) {
          const Json& k = ax[a]["key"];
          if (!k.is_string()) throw Error(at(wa, "key") + ": expected a key path (string), got " + dumpCompact(k));
          newKey(k.get<std::string>(), at(wa, "key"));
          g.keys.push_back(k.get<std::string>());
        } else {
          const Json& ks = requireArray(ax[a]["keys"], at(wa, "keys"));
          for (std::size_t i = 0; i < ks.size(); ++i) {
            if (!ks[i].is_string())
              throw Error(atIndex(at(wa, "keys"), i) + ": expected a key path (string), got " + dumpCompact(ks[i]));
            newKey(ks[i].get<std::string>(), atIndex(at(wa, "keys"), i));
            g.keys.push_back(ks[i].get<std::string>());
          }
        }
        const bool range = ax[a].contains("from") || ax[a].contains("to") || ax[a].contains("count");
        if (range == ax[a].contains("values"))
          throw Error(wa + ": expected either 'values' or 'from', 'to' and 'count', got " + dumpCompact(ax[a]));
        if (range) {
          if (g.keys.size() != 1) throw Error(wa + ": 'from'/'to'/'count' need a single 'key'");
          const double from = requireNumber(requireKey(ax[a], "from", wa), at(wa, "from"));
          const double to = requireNumber(requireKey(ax[a], "to", wa), at(wa, "to"));
          const long long n = requireCount(requireKey(ax[a], "count", wa), at(wa, "count"));
          if (n == 1 && from != to)
            throw Error(at(wa, "count") + ": 1 point cannot span from " + formatValue(from) + " to " + formatValue(to));
          for (long long i = 0; i < n; ++i)
            g.values.push_back({i == n - 1 ? to : from + (to - from) * double(i) / double(n - 1)});
        } else {
          const std::string wvals = at(wa, "values");
          const Json& vals = requireArray(ax[a]["values"], wvals);
          for (std::size_t i = 0; i < vals.size(); ++i) {
            if (vals[i].is_null()) throw Error(atIndex(wvals, i) + ": expected a value, got null");
            if (g.keys.size() == 1) {
              g.values.push_back({vals[i]});
              continue;
            }
            if (!vals[i].is_array() || vals[i].size() != g.keys.size())
              throw Error(atIndex(wvals, i) + ": expected an array of " + std::to_string(g.keys.size()) +
                          " values (one per key), got " + dumpCompact(vals[i]));
            g.values.emplace_back(vals[i].begin(), vals[i].end());
          }
        }
        axes.push_back(std::move(g));
      }
      // The grid's size is checked before it is built (10^10 variations are a
      // named refusal, not an exhausted memory).
      long double total = (long double)d.variations.size(), size = 1;
      std::string shape;
      for (const GridAxis& g : axes) {
        size *= (long double)g.values.size();
        shape += (shape.empty() ? "" : " x ") + std::to_string(g.values.size());
      }
      total += size;
      if (total > (long double)kMaxSweepVariations)
        throw Error(wk + ": " + shape + " = " + formatValue(double(size)) + " variations" +
                    (d.variations.empty() ? "" : " (" + formatValue(double(total)) + " in all)") + "; the limit is " +
                    std::to_string(kMaxSweepVariations) + " variations per sweep");
      sets = makeGridVariations(axes);
    } else if (kind == "list") {
      const Json& items = requireArray(body, wk);
      for (std::size_t i = 0; i < items.size(); ++i) {
        const std::string wi = atIndex(wk, i);
        requireObject(items[i], wi);
        if (items[i].empty()) throw Error(wi + ": expected at least one key path and value, got {}");
        std::vector<SweepSetting> s;
        for (auto it = items[i].begin(); it != items[i].end(); ++it) {
          validatePath(it.key(), wi);
          if (it.value().is_null()) throw Error(at(wi, it.key()) + ": expected a value, got null");
          s.push_back({it.key(), it.value()});
        }
        sets.push_back(std::move(s));
      }
    } else {
      requireObject(body, wk);
      requireKnownKeys(body, {"samples", "seed", "ranges"}, wk);
      const int n = int(requireCount(requireKey(body, "samples", wk), at(wk, "samples")));
      if (d.variations.size() + std::size_t(n) > kMaxSweepVariations)
        throw Error(at(wk, "samples") + ": " + std::to_string(n) + " samples make " +
                    std::to_string(d.variations.size() + std::size_t(n)) + " variations in all; the limit is " +
                    std::to_string(kMaxSweepVariations) + " variations per sweep");
      const Json& seedJ = requireKey(body, "seed", wk);
      if (!seedJ.is_number_integer() || (seedJ.is_number_integer() && !seedJ.is_number_unsigned() &&
                                         seedJ.get<long long>() < 0))
        throw Error(at(wk, "seed") + ": expected a non-negative integer, got " + dumpCompact(seedJ));
      const std::uint64_t seed = seedJ.get<std::uint64_t>();
      const std::string wr = at(wk, "ranges");
      const Json& rj = requireObject(requireKey(body, "ranges", wk), wr);
      if (rj.empty()) throw Error(wr + ": expected at least one \"key\": [min, max], got {}");
      std::vector<SampleRange> ranges;
      for (auto it = rj.begin(); it != rj.end(); ++it) {  // keys in sorted order
        const std::string w = at(wr, it.key());
        validatePath(it.key(), wr);
        const Json& mm = it.value();
        if (!mm.is_array() || mm.size() != 2)
          throw Error(w + ": expected [min, max], got " + dumpCompact(mm));
        SampleRange r{it.key(), requireNumber(mm[0], w + "[0]"), requireNumber(mm[1], w + "[1]")};
        if (!(r.max > r.min))
          throw Error(w + ": expected min < max, got " + dumpCompact(mm));
        blockKeys.insert(r.key);
        ranges.push_back(r);
      }
      sets = kind == "latin_hypercube" ? makeLatinHypercubeVariations(ranges, n, seed)
                                       : makeMonteCarloVariations(ranges, n, seed);
    }
    if (d.variations.size() + sets.size() > kMaxSweepVariations)
      throw Error(wv + ": " + std::to_string(d.variations.size() + sets.size()) +
                  " variations; the limit is " + std::to_string(kMaxSweepVariations) + " variations per sweep");
    d.addVariations(sets);
  }

  if (j.contains("plots")) {
    const std::string wp = at(where, "plots");
    const Json& plots = requireArray(j["plots"], wp);
    for (std::size_t i = 0; i < plots.size(); ++i) {
      const std::string w = atIndex(wp, i);
      const Json& pj = requireObject(plots[i], w);
      requireKnownKeys(pj, {"png", "title", "x", "y", "x_scale", "y_scale", "x_label", "y_label", "series", "panels",
                            "series_label", "panel_label"},
                       w);
      auto text = [&](const char* key, bool required) {
        if (!pj.contains(key)) {
          if (required) throw Error(at(w, key) + ": missing key");
          return std::string();
        }
        if (!pj[key].is_string() || pj[key].get<std::string>().empty())
          throw Error(at(w, key) + ": expected a non-empty string, got " + dumpCompact(pj[key]));
        return pj[key].get<std::string>();
      };
      auto column = [&](const char* key, bool required) {
        const std::string c = text(key, required);
        if (c.empty()) return c;
        if (std::find(d.keys.begin(), d.keys.end(), c) == d.keys.end() &&
            std::find(d.collect.begin(), d.collect.end(), c) == d.collect.end()) {
          std::string known;
          for (const auto& k : d.keys) known += (known.empty() ? "" : ", ") + k;
          for (const auto& k : d.collect) known += (known.empty() ? "" : ", ") + k;
          throw Error(at(w, key) + ": '" + c + "' is neither a varied key nor a collected path; columns: " + known);
        }
        return c;
      };
      SweepPlot p;
      p.png = text("png", true);
      if (p.png.find('/') != std::string::npos || p.png.size() < 5 || p.png.substr(p.png.size() - 4) != ".png")
        throw Error(at(w, "png") + ": expected a file name ending in .png (no folder), got \"" + p.png + "\"");
      p.title = text("title", false);
      p.x = column("x", true);
      p.y = column("y", true);
      p.series = column("series", false);
      p.panels = column("panels", false);
      p.x_label = text("x_label", false);
      p.y_label = text("y_label", false);
      p.series_label = text("series_label", false);
      p.panel_label = text("panel_label", false);
      if (pj.contains("x_scale")) p.x_scale = requireNumber(pj["x_scale"], at(w, "x_scale"));
      if (pj.contains("y_scale")) p.y_scale = requireNumber(pj["y_scale"], at(w, "y_scale"));
      d.plots.push_back(p);
    }
  }
  return d;
}

// --- summaries and rows ---------------------------------------------------------
void collectValues(const SweepDescription& d, SweepRow& row) {
  row.values.assign(d.collect.size(), Json());
  if (!row.ok) return;
  for (std::size_t k = 0; k < d.collect.size(); ++k) {
    const Json* v = KeyPath::parse(d.collect[k], "collect").find(row.summary);
    if (!v) {
      std::string known;
      if (row.summary.is_object())
        for (auto it = row.summary.begin(); it != row.summary.end(); ++it) known += (known.empty() ? "" : ", ") + it.key();
      row.ok = false;
      row.reason = "collect: the run's summary has no '" + d.collect[k] + "' (top-level keys: " + known + ")";
      row.values.assign(d.collect.size(), Json());
      return;
    }
    row.values[k] = *v;
  }
}

namespace {
std::vector<Override> toOverrides(const std::vector<SweepSetting>& settings) {
  std::vector<Override> o;
  for (const auto& s : settings) o.push_back(Override{s.key, s.value});
  return o;
}
}  // namespace

SweepRunFunction makeSceneSweepRun(const SweepDescription& d, PluginRegistry& registry,
                                   const std::string& runFilesDir) {
  const SceneDescription base = SceneDescription::fromFile(d.scene, registry, toOverrides(d.common));
  loadSceneLibraries(base, registry);
  if (d.variations.empty()) throw Error((d.file.empty() ? "sweep" : d.file) + ": no variations");
  const auto errors = base.withOverrides(toOverrides(d.variations.front().settings)).check();
  if (!errors.empty())
    throw Error(d.file + ": variation 0 (" + d.variations.front().id() + "): " + errors.front());
  return [base, runFilesDir](const SweepDescription&, const Variation& v) {
    RunOptions ro;
    ro.plots = false;  // per-run CSV and summary only: no gnuplot process per run
    if (!runFilesDir.empty()) ro.out_dir = runFilesDir + "/" + std::to_string(v.index);
    return runScene(base.withOverrides(toOverrides(v.settings)), ro);
  };
}

std::string sweepStatus(const SweepRow& row) {
  return row.ok ? "ok" : row.outcome.empty() ? "failed" : row.outcome;
}

SweepRow runVariation(const SweepDescription& d, const Variation& v, const SweepRunFunction& run) {
  SweepRow row;
  row.index = v.index;
  const auto w0 = std::chrono::steady_clock::now();
  const double c0 = threadCpuSeconds();
  try {
    // Through text and back: what a journal or an MPI message carries, so rows
    // are identical whichever way they arrive (NaN becomes null).
    row.summary = Json::parse(dumpCompact(run(d, v)));
    row.ok = true;
  } catch (const std::exception& e) {
    row.ok = false;
    if (const auto* named = dynamic_cast<const NamedOutcome*>(&e)) row.outcome = named->status();
    row.reason = e.what();
    for (char& c : row.reason)
      if (c == '\n' || c == '\r') c = ' ';
    row.summary = Json();
  }
  row.cpu_s = threadCpuSeconds() - c0;
  row.wall_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - w0).count();
  collectValues(d, row);
  return row;
}

// --- journal ----------------------------------------------------------------------
std::string sweepJournalLine(const SweepDescription& d, const SweepRow& row) {
  // "run": the run function's outcome (ok, a named outcome or failed); a row
  // failed only by collection keeps its summary and is re-collected on resume.
  const bool ranOk = !row.summary.is_null();
  Json j = {{"variation", row.index},
            {"id", d.variations.at(row.index).id()},
            {"run", ranOk ? "ok" : row.outcome.empty() ? "failed" : row.outcome},
            {"wall_s", row.wall_s},
            {"cpu_s", row.cpu_s}};
  if (ranOk) j["summary"] = row.summary;
  else j["reason"] = row.reason;
  return dumpCompact(j);
}

SweepRow parseSweepJournalLine(const SweepDescription& d, const std::string& line, const std::string& where) {
  Json j;
  requireJsonDepth(line, where);  // bounded input: a corrupt line nesting 1e5 levels is named, not a crash
  try {
    j = Json::parse(line);
  } catch (const std::exception& e) {
    throw Error(where + ": not a journal line (" + e.what() + ")");
  }
  if (!j.is_object() || !j.contains("variation") || !j["variation"].is_number_unsigned() || !j.contains("id") ||
      !j.contains("run"))
    throw Error(where + ": not a journal line: " + line.substr(0, 200));
  SweepRow row;
  row.index = j["variation"].get<std::size_t>();
  if (row.index >= d.variations.size())
    throw Error(where + ": variation " + std::to_string(row.index) + " is beyond the sweep's " +
                std::to_string(d.variations.size()) + " (the output folder belongs to another sweep?)");
  const std::string id = j["id"].get<std::string>(), want = d.variations[row.index].id();
  if (id != want)
    throw Error(where + ": variation " + std::to_string(row.index) + " was '" + id + "' but the sweep now has '" +
                want + "'; the sweep changed: use a new output folder or --fresh");
  row.wall_s = j.value("wall_s", 0.0);
  row.cpu_s = j.value("cpu_s", 0.0);
  if (j["run"] == "ok") {
    row.ok = true;
    row.summary = j.value("summary", Json());
  } else {
    row.ok = false;
    if (j["run"].is_string() && isNamedOutcomeStatus(j["run"].get<std::string>())) row.outcome = j["run"].get<std::string>();
    row.reason = j.value("reason", std::string("(no reason recorded)"));
  }
  collectValues(d, row);
  return row;
}

std::vector<SweepRow> readSweepJournal(const SweepDescription& d, const std::string& dir) {
  const std::string path = dir + "/runs.jsonl";
  std::ifstream in(path, std::ios::binary);
  std::map<std::size_t, SweepRow> rows;
  if (!in) return {};
  std::string line;
  std::vector<std::string> lines;
  std::vector<std::size_t> starts;  // byte offset of each line
  std::size_t offset = 0;
  while (std::getline(in, line)) {
    if (!line.empty()) {
      lines.push_back(line);
      starts.push_back(offset);
    }
    offset += line.size() + 1;
  }
  in.close();
  for (std::size_t n = 0; n < lines.size(); ++n) {
    const std::string where = path + ": line " + std::to_string(n + 1);
    try {
      SweepRow r = parseSweepJournalLine(d, lines[n], where);
      r.resumed = true;
      rows[r.index] = std::move(r);
    } catch (const Error& e) {
      // A run killed while writing leaves at most a torn last line: it is cut
      // off (so the next line appended starts clean) and that run is redone.
      const bool torn = n + 1 == lines.size() && std::string(e.what()).find("not a journal line") != std::string::npos;
      if (!torn) throw;
      std::error_code ec;
      std::filesystem::resize_file(path, starts[n], ec);
      if (ec) throw Error(where + ": cannot cut off the incomplete last line: " + ec.message());
      std::fprintf(stderr, "%s: incomplete last line (an interrupted write) removed; that run is redone\n",
                   where.c_str());
    }
  }
  std::vector<SweepRow> out;
  for (auto& [i, r] : rows) out.push_back(std::move(r));
  return out;
}

// --- outputs ----------------------------------------------------------------------
std::string formatSweepField(const Json& v) {
  if (v.is_null()) return "";
  if (v.is_number_float()) {
    const double x = v.get<double>();
    return std::isfinite(x) ? formatValue(x) : "";
  }
  if (v.is_number_unsigned()) return std::to_string(v.get<std::uint64_t>());
  if (v.is_number_integer()) return std::to_string(v.get<std::int64_t>());
  if (v.is_boolean()) return v.get<bool>() ? "true" : "false";
  if (v.is_string()) return csvQuote(v.get<std::string>());
  return csvQuote(dumpCompact(v));
}

std::string formatSweepCsv(const SweepDescription& d, const std::vector<SweepRow>& rows) {
  std::string s = "variation,status";
  for (const auto& k : d.keys) s += "," + csvQuote(k);
  for (const auto& c : d.collect) s += "," + csvQuote(c);
  s += ",reason\n";
  for (const SweepRow& r : rows) {
    const Variation& v = d.variations.at(r.index);
    s += std::to_string(r.index) + "," + sweepStatus(r);
    for (const auto& k : d.keys) {
      const Json* x = v.find(k);
      s += "," + (x ? formatSweepField(*x) : std::string());
    }
    for (std::size_t k = 0; k < d.collect.size(); ++k)
      s += "," + (k < r.values.size() ? formatSweepField(r.values[k]) : std::string());
    s += "," + csvQuote(r.reason) + "\n";
  }
  return s;
}

std::string formatSweepJson(const SweepDescription& d, const std::vector<SweepRow>& rows) {
  Json runs = Json::array();
  for (const SweepRow& r : rows) {
    Json set = Json::object(), values = Json::object();
    for (const auto& st : d.variations.at(r.index).settings) set[st.key] = st.value;
    for (std::size_t k = 0; k < d.collect.size(); ++k) values[d.collect[k]] = k < r.values.size() ? r.values[k] : Json();
    Json row = {{"variation", r.index}, {"status", sweepStatus(r)}, {"set", set}, {"values", values}};
    if (!r.ok) row["reason"] = r.reason;
    runs.push_back(std::move(row));
  }
  Json common = Json::object();
  for (const auto& st : d.common) common[st.key] = st.value;
  Json j = {{"sweep", d.name}, {"scene", d.scene}, {"set", common},  {"keys", d.keys},
            {"collect", d.collect}, {"variations", d.variations.size()}, {"runs", runs}};
  return j.dump(2, ' ', false, Json::error_handler_t::replace) + "\n";
}

std::unique_ptr<AppendFile> openSweepJournal(const std::string& dir, bool append) {
  return std::make_unique<AppendFile>(dir + "/runs.jsonl", append);
}

double processCpuSeconds() {
  rusage ru;
  getrusage(RUSAGE_SELF, &ru);
  return ru.ru_utime.tv_sec + 1e-6 * ru.ru_utime.tv_usec + ru.ru_stime.tv_sec + 1e-6 * ru.ru_stime.tv_usec;
}

void writeSweepOutputs(const SweepDescription& d, const SweepResult& r, const std::string& dir) {
  writeFileAtomic(dir + "/results.csv", formatSweepCsv(d, r.rows));
  {
    Json results = Json::parse(formatSweepJson(d, r.rows));
    if (r.partial) results["partial"] = true;
    writeFileAtomic(dir + "/results.json", r.partial ? results.dump(2, ' ', false, Json::error_handler_t::replace) + "\n"
                                                     : formatSweepJson(d, r.rows));
  }
  double runWall = 0, runCpu = 0;
  for (const auto& row : r.rows)
    if (!row.resumed) runWall += row.wall_s, runCpu += row.cpu_s;
  Json stats = {{"sweep", d.name},
                {"runner", r.runner},
                {"workers", r.workers},
                {"variations", d.variations.size()},
                {"ran", r.ran},
                {"failed", r.failed},
                {"outcomes", r.outcomes},
                {"resumed", r.resumed},
                {"partial", r.partial},
                {"wall_s", r.wall_s},
                {"cpu_s", r.cpu_s},
                {"run_wall_s_sum", runWall},
                {"run_cpu_s_sum", runCpu},
                // Worker time not spent inside a run, per run: scheduling, messages,
                // journal writes, and idle workers at the tail of the sweep.
                {"overhead_ms_per_run", r.ran ? 1e3 * (r.workers * r.wall_s - runWall) / r.ran : 0.0},
                {"host", [] {
                   char h[256] = {0};
                   gethostname(h, sizeof h - 1);
                   return std::string(h);
                 }()}};
  if (r.partial) stats["interrupted_by"] = r.interrupted_by;
  writeFileAtomic(dir + "/sweep_stats.json", stats.dump(2) + "\n");
}

std::function<void(const SweepProgress&)> sweepProgressPrinter(const std::string& label) {
  const bool tty = isatty(fileno(stderr));
  auto last = std::make_shared<double>(-1e9);
  return [label, tty, last](const SweepProgress& p) {
    const std::size_t finished = p.done + p.skipped;
    const bool end = finished == p.total;
    if (!tty && !end && p.elapsed_s - *last < 5.0) return;
    *last = p.elapsed_s;
    char eta[64] = "";
    if (!end && p.eta_s >= 0) std::snprintf(eta, sizeof eta, ", about %.0f s left", p.eta_s);
    std::string named;
    for (const auto& [status, count] : p.outcomes) named += ", " + std::to_string(count) + " " + status;
    char skipped[64] = "";
    if (p.skipped) std::snprintf(skipped, sizeof skipped, ", %zu from the journal", p.skipped);
    std::fprintf(stderr, "%s%s: %zu/%zu runs (%zu failed%s%s), %.1f s%s%s", tty ? "\r\033[K" : "", label.c_str(),
                 finished, p.total, p.failed, named.c_str(), skipped, p.elapsed_s, eta, tty && !end ? "" : "\n");
    std::fflush(stderr);
  };
}

std::vector<std::size_t> prepareSweepRun(const SweepDescription& d, const SweepOptions& o, SweepResult& res,
                                         std::unique_ptr<AppendFile>& journal) {
  const std::size_t n = d.variations.size();
  res.rows.resize(n);
  std::vector<char> have(n, 0);
  journal.reset();
  if (!o.out_dir.empty()) {
    std::error_code ec;
    std::filesystem::create_directories(o.out_dir, ec);
    if (ec) throw Error("cannot create output folder '" + o.out_dir + "': " + ec.message());
    if (o.resume) {
      for (SweepRow& r : readSweepJournal(d, o.out_dir)) {
        if (sweepStatus(r) == "failed" && o.retry_failed) continue;
        have[r.index] = 1;
        res.rows[r.index] = std::move(r);
        ++res.resumed;
      }
    }
    journal = openSweepJournal(o.out_dir, o.resume);
  }
  std::vector<std::size_t> pending;
  for (std::size_t i = 0; i < n; ++i)
    if (!have[i]) pending.push_back(i);
  return pending;
}

void finishSweepRun(const SweepDescription& d, const SweepOptions& o, SweepResult& res,
                    std::chrono::steady_clock::time_point start, double cpu0) {
  for (const auto& r : res.rows) {
    if (sweepStatus(r) == "failed") ++res.failed;
    if (!r.outcome.empty()) ++res.outcomes[r.outcome];
  }
  res.wall_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  res.cpu_s = processCpuSeconds() - cpu0;
  if (!o.out_dir.empty()) writeSweepOutputs(d, res, o.out_dir);
}

// --- the thread runner ------------------------------------------------------------
SweepResult runSweep(const SweepDescription& d, const SweepRunFunction& run, const SweepOptions& o) {
  if (o.threads < 1) throw Error("sweep: --threads must be at least 1, got " + std::to_string(o.threads));
  const auto t0 = std::chrono::steady_clock::now();
  const double cpu0 = processCpuSeconds();
  const std::size_t n = d.variations.size();
  SweepResult res;
  res.runner = "threads";
  std::unique_ptr<AppendFile> journal;
  const std::vector<std::size_t> pending = prepareSweepRun(d, o, res, journal);

  std::mutex mu;
  SweepProgress prog;
  prog.total = n;
  prog.skipped = res.resumed;
  std::string journalError;
  std::vector<char> finished(n, 1);  // resumed or run now; the pending ones until they are
  for (std::size_t i : pending) finished[i] = 0;
  auto record = [&](SweepRow&& row) {
    std::lock_guard<std::mutex> lock(mu);
    // A run cut short by SIGINT/SIGTERM is not a result: not journaled, run again on resume.
    if (!row.ok && interruptSignal()) return;
    finished[row.index] = 1;
    if (journal && journalError.empty()) {
      try {
        journal->appendLine(sweepJournalLine(d, row));
      } catch (const Error& e) {
        journalError = e.what();
      }
    }
    ++prog.done;
    if (sweepStatus(row) == "failed") ++prog.failed;
    if (!row.outcome.empty()) ++prog.outcomes[row.outcome];
    res.rows[row.index] = std::move(row);
    prog.elapsed_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    prog.eta_s = prog.elapsed_s / prog.done * double(pending.size() - prog.done);
    if (o.progress) o.progress(prog);
  };
  std::atomic<std::size_t> next{0};
  auto worker = [&] {
    // A safe point between variations: after SIGINT/SIGTERM no new one starts.
    for (std::size_t k; !interruptSignal() && (k = next++) < pending.size();)
      record(runVariation(d, d.variations[pending[k]], run));
  };
  const int threads = int(std::min<std::size_t>(std::size_t(o.threads), std::max<std::size_t>(1, pending.size())));
  if (threads == 1) {
    worker();  // serial: in the calling thread
  } else {
    std::vector<std::thread> pool;
    for (int t = 0; t < threads; ++t) pool.emplace_back(worker);
    for (auto& t : pool) t.join();
  }
  if (!journalError.empty()) throw Error(journalError);
  if (journal) journal->close();
  if (pending.empty() && o.progress) {
    prog.elapsed_s = 0;
    o.progress(prog);
  }
  res.workers = threads;
  res.ran = prog.done;
  if (const int sig = interruptSignal()) {
    // Interrupted: the finished rows (journal and results.csv), marked partial.
    std::vector<SweepRow> rows;
    for (std::size_t i = 0; i < n; ++i)
      if (finished[i]) rows.push_back(std::move(res.rows[i]));
    const std::size_t have = rows.size();
    res.rows = std::move(rows);
    res.partial = true;
    res.interrupted_by = signalName(sig);
    finishSweepRun(d, o, res, t0, cpu0);
    throw Interrupted(sig, "interrupted by " + signalName(sig) + ": " + std::to_string(have) + " of " +
                               std::to_string(n) + " variations done" +
                               (o.out_dir.empty() ? std::string()
                                                  : ", in " + o.out_dir + "/results.csv (partial: true in "
                                                    "sweep_stats.json and results.json); run again to resume"));
  }
  finishSweepRun(d, o, res, t0, cpu0);
  return res;
}

int hardwareThreads() { return int(std::max(1u, std::thread::hardware_concurrency())); }

JobsTiming runJobs(std::size_t n, int threads, const std::function<void(std::size_t)>& job) {
  if (threads < 1) throw Error("runJobs: threads must be at least 1, got " + std::to_string(threads));
  SweepDescription d;
  d.name = "jobs";
  d.variations.resize(n);
  for (std::size_t i = 0; i < n; ++i) d.variations[i].index = i;
  SweepOptions o;
  o.threads = threads;
  const SweepResult r = runSweep(
      d,
      [&job](const SweepDescription&, const Variation& v) {
        job(v.index);
        return Json::object();
      },
      o);
  for (const SweepRow& row : r.rows)
    if (!row.ok) throw Error(row.reason);
  return {r.wall_s, r.cpu_s, r.workers};
}

}  // namespace vdyn
