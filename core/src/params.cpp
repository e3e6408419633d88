#include "vdyn/core/params.h"

#include <algorithm>
#include <climits>
#include <cstdint>
#include <cstdlib>
#include <fstream>
#include <functional>
#include <map>
#include <mutex>
#include <set>
#include <sstream>

#include <dlfcn.h>
#include <sys/stat.h>

namespace vdyn {

namespace {
/// A SAX pass that only follows the key path, so a syntax error, a number out
/// of range (1e999) or a duplicate key can be reported with where it is.
class PathSax : public nlohmann::json_sax<Json> {
 public:
  std::string error;       ///< empty when the text parsed
  std::size_t position = 0;
  std::string path() const {
    std::string p;
    for (const Frame& f : frames_) {
      if (f.obj) {
        if (!f.key.empty() || f.keys.size()) p += (p.empty() ? "" : ".") + f.key;
      } else if (f.index >= 0) {
        p += "[" + std::to_string(f.index) + "]";
      }
    }
    return p;
  }
  bool null() override { return value(); }
  bool boolean(bool) override { return value(); }
  bool number_integer(number_integer_t) override { return value(); }
  bool number_unsigned(number_unsigned_t) override { return value(); }
  bool number_float(number_float_t, const string_t&) override { return value(); }
  bool string(string_t&) override { return value(); }
  bool binary(binary_t&) override { return value(); }
  bool start_object(std::size_t) override {
    value();
    frames_.push_back({true, {}, "", -1});
    return true;
  }
  bool key(string_t& k) override {
    Frame& f = frames_.back();
    f.key = k;
    if (!f.keys.insert(k).second) {
      error = "duplicate key '" + k + "' (the second would silently replace the first)";
      return false;
    }
    return true;
  }
  bool end_object() override {
    frames_.pop_back();
    return true;
  }
  bool start_array(std::size_t) override {
    value();
    frames_.push_back({false, {}, "", -1});
    return true;
  }
  bool end_array() override {
    frames_.pop_back();
    return true;
  }
  bool parse_error(std::size_t pos, const std::string& token, const nlohmann::detail::exception& ex) override {
    // pos is just past the offending token: point at its first character.
    position = pos >= token.size() ? pos - token.size() + 1 : pos;
    std::string what = ex.what();
    // "[json.exception.parse_error.101] parse error at line 1, column 2: syntax error ..." -> the reason
    const auto colon = what.find(": ", what.find(']'));
    if (ex.id == 406) what = "number out of range (not a finite double): " + token;
    else if (colon != std::string::npos) what = what.substr(colon + 2);
    error = what;
    return false;
  }

 private:
  struct Frame {
    bool obj;
    std::set<std::string> keys;
    std::string key;
    long index;
  };
  bool value() {
    if (!frames_.empty() && !frames_.back().obj) ++frames_.back().index;
    return true;
  }
  std::vector<Frame> frames_;
};

std::string lineColumn(const std::string& text, std::size_t pos) {
  pos = std::min(pos, text.size());
  std::size_t line = 1, col = 1;
  for (std::size_t i = 0; i + 1 < pos; ++i) {
    if (text[i] == '\n') {
      ++line;
      col = 1;
    } else {
      ++col;
    }
  }
  return "line " + std::to_string(line) + ", column " + std::to_string(col);
}
}  // namespace

void requireJsonDepth(const std::string& text, const std::string& name) {
  std::size_t depth = 0, deepest = 0, first = std::string::npos;
  const std::size_t n = text.size();
  for (std::size_t i = 0; i < n; ++i) {
    const char c = text[i];
    if (c == '"') {  // a string: skip to its closing quote
      for (++i; i < n && text[i] != '"'; ++i)
        if (text[i] == '\\') ++i;
    } else if (c == '/' && i + 1 < n && text[i + 1] == '/') {
      while (i < n && text[i] != '\n') ++i;
    } else if (c == '/' && i + 1 < n && text[i + 1] == '*') {
      const std::size_t end = text.find("*/", i + 2);
      i = end == std::string::npos ? n : end + 1;
    } else if (c == '[' || c == '{') {
      if (++depth > deepest) deepest = depth;
      if (depth > kMaxJsonDepth && first == std::string::npos) first = i + 1;
    } else if ((c == ']' || c == '}') && depth > 0) {
      --depth;
    }
  }
  if (first != std::string::npos)
    throw Error(name + " nests " + std::to_string(deepest) + " arrays/objects deep (" + lineColumn(text, first) +
                " passes the limit of " + std::to_string(kMaxJsonDepth) + ")");
}

Json parseJsonText(const std::string& text, const std::string& name) {
  if (text.find_first_not_of(" \t\r\n") == std::string::npos) throw Error(name + " is empty (expected a JSON object)");
  requireJsonDepth(text, name);
  PathSax sax;
  bool ok = false;
  try {
    ok = Json::sax_parse(text, &sax, Json::input_format_t::json, /*strict=*/true, /*ignore_comments=*/true);
  } catch (const std::exception& e) {
    sax.error = e.what();
  }
  if (!ok || !sax.error.empty()) {
    const std::string path = sax.path();
    throw Error(name + " is not valid JSON (" + lineColumn(text, sax.position) +
                (path.empty() ? "" : ", key " + path) + "): " + (sax.error.empty() ? "parse error" : sax.error));
  }
  try {
    return Json::parse(text, nullptr, true, /*ignore_comments=*/true);
  } catch (const nlohmann::json::exception& e) {
    throw Error(name + " is not valid JSON: " + e.what());
  }
}

Json readJsonFile(const std::string& path) {
  struct stat st;
  if (stat(path.c_str(), &st) == 0 && S_ISDIR(st.st_mode))
    throw Error("data file '" + path + "' is a folder, not a JSON file");
  if (stat(path.c_str(), &st) == 0 && S_ISREG(st.st_mode) && std::uintmax_t(st.st_size) > kMaxJsonFileBytes)
    throw Error("data file '" + path + "' is " + std::to_string(st.st_size) + " bytes (limit " +
                std::to_string(kMaxJsonFileBytes) + " bytes, 64 MiB)");
  std::ifstream in(path, std::ios::binary);
  if (!in) throw Error("cannot open data file '" + path + "'");
  // Read at most the limit (a device or a pipe has no size to check first).
  std::string text;
  char buf[65536];
  while (in.read(buf, sizeof buf) || in.gcount() > 0) {
    text.append(buf, std::size_t(in.gcount()));
    if (text.size() > kMaxJsonFileBytes)
      throw Error("data file '" + path + "' is more than " + std::to_string(kMaxJsonFileBytes) +
                  " bytes (the limit, 64 MiB)");
  }
  if (in.bad()) throw Error("cannot read data file '" + path + "'");
  return parseJsonText(text, "data file '" + path + "'");
}

std::vector<std::string> dataSearchPath() {
  std::vector<std::string> dirs;
  if (const char* env = std::getenv("VDYN_DATA_PATH")) {
    std::string list(env);
    size_t start = 0;
    while (start <= list.size()) {
      const size_t end = std::min(list.find(':', start), list.size());
      if (end > start) dirs.push_back(list.substr(start, end - start));
      start = end + 1;
    }
  }
  // The object file holding this function: libvdyn_core.so (or the program,
  // for a static build); the installed data folder is relative to it.
  std::string installed;
  Dl_info info;
  if (dladdr(reinterpret_cast<void*>(&dataSearchPath), &info) != 0 && info.dli_fname != nullptr) {
    std::string lib(info.dli_fname);
    const size_t slash = lib.find_last_of('/');
    installed = (slash == std::string::npos ? std::string(".") : lib.substr(0, slash)) + "/" + VDYN_LIB_TO_DATA;
  }
  struct stat st;
  if (!installed.empty() && stat(installed.c_str(), &st) == 0 && S_ISDIR(st.st_mode))
    dirs.push_back(installed);
  else
    dirs.push_back(VDYN_BUILD_DATA_DIR);
  return dirs;
}

std::string resolveDataPath(const std::string& name) {
  struct stat st;
  if (stat(name.c_str(), &st) == 0) return name;
  const std::vector<std::string> dirs = dataSearchPath();
  std::string looked = "the working directory";
  if (name.empty() || name[0] != '/') {
    for (const std::string& dir : dirs) {
      const std::string candidate = dir + "/" + name;
      if (stat(candidate.c_str(), &st) == 0) return candidate;
      looked += ", " + dir;
    }
  }
  throw Error("data file '" + name + "' not found (looked in " + looked + ")");
}

static bool fileExists(const std::string& p) {
  struct stat st;
  return stat(p.c_str(), &st) == 0 && S_ISREG(st.st_mode);
}

std::string resolveDataPath(const std::string& name, const std::string& namingFile) {
  struct stat st;
  if (!name.empty() && name[0] == '/' && stat(name.c_str(), &st) == 0 && S_ISDIR(st.st_mode))
    throw Error(namingFile + ": data file '" + name + "' is a folder, not a JSON file");
  if (!name.empty() && name[0] == '/') {
    if (fileExists(name)) return name;
    throw Error(namingFile + ": data file '" + name + "' not found");
  }
  const auto slash = namingFile.find_last_of('/');
  const std::string here = slash == std::string::npos ? "." : namingFile.substr(0, slash);
  if (fileExists(here + "/" + name)) return here == "." ? name : here + "/" + name;
  std::string looked = here;
  for (const auto& dir : dataSearchPath()) {
    if (fileExists(dir + "/" + name)) return dir + "/" + name;
    looked += ", " + dir;
  }
  throw Error(namingFile + ": data file '" + name + "' not found (looked in " + looked + ")");
}

struct ParamReader::Tracker {
  std::mutex mutex;
  std::map<const Json*, std::set<std::string>> queried;  ///< keys asked for, per object node
  std::set<const Json*> opened;                          ///< nodes opened as readers (checked recursively)
  std::set<const Json*> consumed;                        ///< nodes taken over by raw() or mergedWith()
  std::shared_ptr<ParamReader> patch;                    ///< mergedWith(): the patch, checked first
  std::string baseWhere;                                 ///< mergedWith(): where the base came from
};

ParamReader::ParamReader(std::shared_ptr<const Json> root, const Json* node, std::string where)
    : ParamReader(std::move(root), node, std::move(where), std::make_shared<Tracker>()) {}

ParamReader::ParamReader(std::shared_ptr<const Json> root, const Json* node, std::string where,
                         std::shared_ptr<Tracker> tracker)
    : root_(std::move(root)), tracker_(std::move(tracker)), node_(node), where_(std::move(where)) {
  if (!node_->is_object()) {
    std::string w = where_;
    if (!w.empty() && w.back() == ':') w.pop_back();
    throw Error(w + ": expected an object, got " + std::string(node_->type_name()));
  }
  std::lock_guard<std::mutex> lock(tracker_->mutex);
  tracker_->opened.insert(node_);
}

void ParamReader::mark(const std::string& key) const {
  std::lock_guard<std::mutex> lock(tracker_->mutex);
  tracker_->queried[node_].insert(key);
}

std::vector<std::string> ParamReader::queriedKeys() const {
  std::lock_guard<std::mutex> lock(tracker_->mutex);
  const auto q = tracker_->queried.find(node_);
  if (q == tracker_->queried.end()) return {};
  return {q->second.begin(), q->second.end()};
}

namespace {
std::string baseName(const std::string& path) { return path.substr(path.find_last_of('/') + 1); }

/// Reads a data file; a file with "based_on": "<other file>" is that file with
/// its own keys merged over it (RFC 7396 merge patch), so a variant names only
/// what it changes. Chains are followed (at most 8 deep); a cycle is an error.
Json readWithBase(const std::string& resolved, std::vector<std::string>& chain) {
  Json j = readJsonFile(resolved);
  const std::string name = baseName(resolved);
  if (!j.is_object())
    throw Error(name + ": expected a JSON object at the top level, got " + std::string(j.type_name()));
  if (!j.contains("based_on")) return j;
  if (!j["based_on"].is_string())
    throw Error(name + ": based_on: expected a data file name, got " + j["based_on"].dump());
  chain.push_back(resolved);
  const std::string next = resolveDataPath(j["based_on"].get<std::string>(), resolved);
  for (const auto& c : chain) {
    char a[PATH_MAX], b[PATH_MAX];
    const bool same = (realpath(c.c_str(), a) && realpath(next.c_str(), b)) ? std::string(a) == b : c == next;
    if (same) {
      std::string cycle;
      for (const auto& k : chain) cycle += baseName(k) + " -> ";
      throw Error(name + ": based_on: the variants form a cycle: " + cycle + baseName(next));
    }
  }
  if (chain.size() >= 8) throw Error(name + ": based_on: chain deeper than 8 files");
  Json base = readWithBase(next, chain);
  j.erase("based_on");
  base.merge_patch(j);
  return base;
}
}  // namespace

ParamReader ParamReader::fromFile(const std::string& path) {
  const std::string resolved = resolveDataPath(path);
  std::vector<std::string> chain;
  auto root = std::make_shared<const Json>(readWithBase(resolved, chain));
  return ParamReader(root, root.get(), baseName(resolved) + ":");
}

ParamReader ParamReader::fromJson(Json j, std::string where) {
  auto root = std::make_shared<const Json>(std::move(j));
  return ParamReader(root, root.get(), std::move(where) + ":");
}

std::string ParamReader::at(const std::string& key) const {
  if (!where_.empty() && where_.back() == ':') return where_ + " " + key;
  return where_ + "." + key;
}

bool ParamReader::has(const std::string& key) const {
  mark(key);
  return node_->contains(key);
}

const Json& ParamReader::require(const std::string& key) const {
  mark(key);
  auto it = node_->find(key);
  if (it == node_->end()) throw Error(at(key) + ": missing key");
  return *it;
}

static double asNumber(const Json& v, const std::string& where) {
  if (!v.is_number())
    throw Error(where + ": expected a number, got " + std::string(v.type_name()) + " " + v.dump());
  return requireFinite(v.get<double>(), where);
}

double ParamReader::number(const std::string& key) const { return asNumber(require(key), at(key)); }

double ParamReader::numberOr(const std::string& key, double fallback) const {
  return has(key) ? number(key) : fallback;
}

std::vector<double> ParamReader::numbers(const std::string& key) const {
  const Json& v = require(key);
  if (!v.is_array()) throw Error(at(key) + ": expected an array of numbers, got " + v.dump());
  std::vector<double> out;
  for (std::size_t i = 0; i < v.size(); ++i)
    out.push_back(asNumber(v[i], at(key) + "[" + std::to_string(i) + "]"));
  return out;
}

SimTK::Vec3 ParamReader::vec3(const std::string& key) const {
  const auto v = numbers(key);
  if (v.size() != 3)
    throw Error(at(key) + ": expected 3 numbers [x, y, z], got " + std::to_string(v.size()));
  return SimTK::Vec3(v[0], v[1], v[2]);
}

SimTK::Vec3 ParamReader::vec3Or(const std::string& key, const SimTK::Vec3& fallback) const {
  return has(key) ? vec3(key) : fallback;
}

std::string ParamReader::string(const std::string& key) const {
  const Json& v = require(key);
  if (!v.is_string()) throw Error(at(key) + ": expected a string, got " + v.dump());
  return v.get<std::string>();
}

std::string ParamReader::stringOr(const std::string& key, const std::string& fallback) const {
  return has(key) ? string(key) : fallback;
}

bool ParamReader::boolean(const std::string& key) const {
  const Json& v = require(key);
  if (!v.is_boolean()) throw Error(at(key) + ": expected true or false, got " + v.dump());
  return v.get<bool>();
}

bool ParamReader::booleanOr(const std::string& key, bool fallback) const {
  return has(key) ? boolean(key) : fallback;
}

int ParamReader::integer(const std::string& key) const {
  const Json& v = require(key);
  if (!v.is_number_integer()) throw Error(at(key) + ": expected an integer, got " + v.dump());
  return v.get<int>();
}

ParamReader ParamReader::child(const std::string& key) const {
  const Json& v = require(key);
  if (!v.is_object()) throw Error(at(key) + ": expected an object, got " + v.dump());
  return ParamReader(root_, &v, at(key), tracker_);
}

std::vector<ParamReader> ParamReader::array(const std::string& key) const {
  const Json& v = require(key);
  if (!v.is_array()) throw Error(at(key) + ": expected an array, got " + v.dump());
  std::vector<ParamReader> out;
  for (std::size_t i = 0; i < v.size(); ++i)
    out.push_back(ParamReader(root_, &v[i], at(key) + "[" + std::to_string(i) + "]", tracker_));
  return out;
}

const Json& ParamReader::raw(const std::string& key) const {
  const Json& v = require(key);
  std::lock_guard<std::mutex> lock(tracker_->mutex);
  tracker_->consumed.insert(&v);
  return v;
}

namespace {
std::size_t editDistance(const std::string& a, const std::string& b) {
  std::vector<std::size_t> d(b.size() + 1);
  for (std::size_t j = 0; j <= b.size(); ++j) d[j] = j;
  for (std::size_t i = 1; i <= a.size(); ++i) {
    std::size_t prev = d[0];
    d[0] = i;
    for (std::size_t j = 1; j <= b.size(); ++j) {
      const std::size_t cur = d[j];
      d[j] = std::min({d[j] + 1, d[j - 1] + 1, prev + (a[i - 1] == b[j - 1] ? 0 : 1)});
      prev = cur;
    }
  }
  return d[b.size()];
}

/// The candidate closest to `key`: edit distance, less twice the common prefix
/// (so "gravity" finds "gravity_m_per_s2", a key without its unit); empty when
/// even the closest is too far to be a plausible misspelling.
std::string nearest(const std::string& key, const std::set<std::string>& candidates) {
  std::string best;
  long bestD = 0;
  for (const auto& c : candidates) {
    std::size_t prefix = 0;
    while (prefix < key.size() && prefix < c.size() && key[prefix] == c[prefix]) ++prefix;
    const long dist = long(editDistance(key, c)) - 2 * long(prefix);
    if (best.empty() || dist < bestD) {
      bestD = dist;
      best = c;
    }
  }
  return bestD <= std::max<long>(2, long(key.size()) / 3) ? best : std::string();
}

std::string unknownKey(const std::string& path, const std::string& key, const std::set<std::string>& asked) {
  const std::string hint = nearest(key, asked);
  return path + ": unknown key" + (hint.empty() ? "" : " (did you mean '" + hint + "'?)");
}

std::string join(const std::string& where, const std::string& path) {
  if (!where.empty() && where.back() == ':') return where + " " + path;
  return where + "." + path;
}
}  // namespace

std::vector<std::string> ParamReader::unreadKeys() const {
  std::vector<std::string> problems;
  std::lock_guard<std::mutex> lock(tracker_->mutex);
  const Tracker& t = *tracker_;
  const std::function<void(const Json&, const std::string&)> walk = [&](const Json& node, const std::string& w) {
    if (t.consumed.count(&node)) return;
    if (node.is_array()) {
      for (std::size_t i = 0; i < node.size(); ++i) walk(node[i], w + "[" + std::to_string(i) + "]");
      return;
    }
    if (!node.is_object() || !t.opened.count(&node)) return;
    static const std::set<std::string> none;
    const auto q = t.queried.find(&node);
    const std::set<std::string>& asked = q == t.queried.end() ? none : q->second;
    for (auto it = node.begin(); it != node.end(); ++it) {
      if (!it.key().empty() && it.key()[0] == '_') continue;  // comment key
      const std::string path = join(w, it.key());
      if (!asked.count(it.key())) {
        problems.push_back(unknownKey(path, it.key(), asked));
        continue;
      }
      walk(*it, path);
    }
  };
  if (t.patch && node_ == root_.get()) {
    // Keys of the patch the merged reader never asked for, named as the user wrote them.
    const std::function<void(const Json&, const Json&, const std::string&)> walkPatch =
        [&](const Json& patch, const Json& merged, const std::string& w) {
          if (!patch.is_object() || !merged.is_object() || t.consumed.count(&merged)) return;
          static const std::set<std::string> none;
          const auto q = t.queried.find(&merged);
          const std::set<std::string>& asked = q == t.queried.end() ? none : q->second;
          for (auto it = patch.begin(); it != patch.end(); ++it) {
            if (!it.key().empty() && it.key()[0] == '_') continue;
            const std::string path = join(w, it.key());
            if (!asked.count(it.key())) {
              problems.push_back(unknownKey(path, it.key(), asked));
              continue;
            }
            const auto m = merged.find(it.key());
            if (m != merged.end() && t.opened.count(&*m)) walkPatch(*it, *m, path);
          }
        };
    walkPatch(t.patch->json(), *node_, t.patch->where());
  }
  if (problems.empty()) walk(*node_, t.patch && node_ == root_.get() && !t.baseWhere.empty() ? t.baseWhere : where_);
  return problems;
}

void ParamReader::requireAllKeysRead() const {
  const std::vector<std::string> problems = unreadKeys();
  if (problems.empty()) return;
  std::string msg;
  for (const auto& p : problems) msg += (msg.empty() ? "" : "; ") + p;
  throw Error(msg);
}

void ParamReader::markAllRead() const {
  std::lock_guard<std::mutex> lock(tracker_->mutex);
  tracker_->consumed.insert(node_);
}

ParamReader ParamReader::mergedWith(const ParamReader& patch) const {
  Json m = *node_;
  m.merge_patch(*patch.node_);
  {
    std::lock_guard<std::mutex> lock(tracker_->mutex);
    tracker_->consumed.insert(node_);
  }
  {
    std::lock_guard<std::mutex> lock(patch.tracker_->mutex);
    patch.tracker_->consumed.insert(patch.node_);
  }
  auto root = std::make_shared<const Json>(std::move(m));
  auto tracker = std::make_shared<Tracker>();
  tracker->patch = std::make_shared<ParamReader>(patch);
  // Named by the patch (what the user wrote); its requireAllKeysRead names an
  // unknown key of the base by the base's own location.
  ParamReader merged(root, root.get(), patch.where_, tracker);
  tracker->baseWhere = where_;
  return merged;
}

}  // namespace vdyn
