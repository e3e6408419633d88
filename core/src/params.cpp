#include "vdyn/core/params.h"

#include <algorithm>
#include <cstdlib>
#include <fstream>
#include <sys/stat.h>

namespace vdyn {

Json readJsonFile(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw Error("cannot open data file '" + path + "'");
  try {
    return Json::parse(in, nullptr, true, /*ignore_comments=*/true);
  } catch (const nlohmann::json::parse_error& e) {
    throw Error("data file '" + path + "' is not valid JSON: " + e.what());
  }
}

std::vector<std::string> dataSearchPath() {
  std::vector<std::string> path;
  if (const char* env = std::getenv("VDYN_DATA_PATH")) {
    std::string item;
    for (const char* c = env;; ++c) {
      if (*c == ':' || *c == 0) {
        if (!item.empty()) path.push_back(item);
        item.clear();
        if (*c == 0) break;
      } else {
        item += *c;
      }
    }
  }
  path.push_back(VDYN_DATA_DIR);
  return path;
}

static bool fileExists(const std::string& p) {
  struct stat st;
  return stat(p.c_str(), &st) == 0 && S_ISREG(st.st_mode);
}

static std::string joinFolders(const std::vector<std::string>& folders) {
  std::string s;
  for (const auto& f : folders) s += (s.empty() ? "" : ", ") + f;
  return s;
}

std::string resolveDataPath(const std::string& name) {
  if (fileExists(name)) return name;
  if (!name.empty() && name[0] != '/')
    for (const auto& dir : dataSearchPath())
      if (fileExists(dir + "/" + name)) return dir + "/" + name;
  throw Error("data file '" + name + "' not found (looked in the working directory and " +
              joinFolders(dataSearchPath()) + ")");
}

std::string resolveDataPath(const std::string& name, const std::string& namingFile) {
  if (!name.empty() && name[0] == '/') {
    if (fileExists(name)) return name;
    throw Error(namingFile + ": data file '" + name + "' not found");
  }
  const auto slash = namingFile.find_last_of('/');
  const std::string here = slash == std::string::npos ? "." : namingFile.substr(0, slash);
  if (fileExists(here + "/" + name)) return here == "." ? name : here + "/" + name;
  for (const auto& dir : dataSearchPath())
    if (fileExists(dir + "/" + name)) return dir + "/" + name;
  throw Error(namingFile + ": data file '" + name + "' not found (looked in " + here + ", " +
              joinFolders(dataSearchPath()) + ")");
}

ParamReader::ParamReader(std::shared_ptr<const Json> root, const Json* node, std::string where)
    : root_(std::move(root)), node_(node), where_(std::move(where)) {
  if (!node_->is_object()) throw Error(where_ + ": expected an object");
}

namespace {
/// Reads a data file; a file with "based_on": "<other file>" is that file with
/// its own keys merged over it (RFC 7396 merge patch), so a variant names only
/// what it changes. Chains are followed (at most 8 deep).
Json readWithBase(const std::string& resolved, int depth) {
  Json j = readJsonFile(resolved);
  if (!j.is_object() || !j.contains("based_on")) return j;
  const std::string name = resolved.substr(resolved.find_last_of('/') + 1);
  if (!j["based_on"].is_string()) throw Error(name + ": based_on: expected a data file name");
  if (depth >= 8) throw Error(name + ": based_on: chain deeper than 8 files (a cycle?)");
  Json base = readWithBase(resolveDataPath(j["based_on"].get<std::string>(), resolved), depth + 1);
  j.erase("based_on");
  base.merge_patch(j);
  return base;
}
}  // namespace

ParamReader ParamReader::fromFile(const std::string& path) {
  const std::string resolved = resolveDataPath(path);
  auto root = std::make_shared<const Json>(readWithBase(resolved, 0));
  const std::string base = resolved.substr(resolved.find_last_of('/') + 1);
  return ParamReader(root, root.get(), base + ":");
}

ParamReader ParamReader::fromJson(Json j, std::string where) {
  auto root = std::make_shared<const Json>(std::move(j));
  return ParamReader(root, root.get(), std::move(where) + ":");
}

std::string ParamReader::at(const std::string& key) const {
  if (!where_.empty() && where_.back() == ':') return where_ + " " + key;
  return where_ + "." + key;
}

void ParamReader::note(const std::string& key) const { record_->asked.insert({node_, key}); }

bool ParamReader::has(const std::string& key) const {
  note(key);
  return node_->contains(key);
}

const Json& ParamReader::require(const std::string& key) const {
  note(key);
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
  ParamReader c(root_, &v, at(key));
  c.record_ = record_;
  record_->visited.insert(&v);
  return c;
}

std::vector<ParamReader> ParamReader::array(const std::string& key) const {
  const Json& v = require(key);
  if (!v.is_array()) throw Error(at(key) + ": expected an array, got " + v.dump());
  std::vector<ParamReader> out;
  for (std::size_t i = 0; i < v.size(); ++i) {
    out.emplace_back(root_, &v[i], at(key) + "[" + std::to_string(i) + "]");
    out.back().record_ = record_;
    record_->visited.insert(&v[i]);
  }
  return out;
}

namespace {
std::size_t editDistance(const std::string& a, const std::string& b) {
  std::vector<std::size_t> row(b.size() + 1);
  for (std::size_t j = 0; j <= b.size(); ++j) row[j] = j;
  for (std::size_t i = 1; i <= a.size(); ++i) {
    std::size_t diag = row[0];
    row[0] = i;
    for (std::size_t j = 1; j <= b.size(); ++j) {
      const std::size_t up = row[j];
      row[j] = std::min({row[j] + 1, row[j - 1] + 1, diag + (a[i - 1] == b[j - 1] ? 0 : 1)});
      diag = up;
    }
  }
  return row[b.size()];
}
}  // namespace

void ParamReader::collectUnread(const Json& node, const std::string& where, std::vector<std::string>& out) const {
  auto loc = [&](const std::string& key) {
    return (!where.empty() && where.back() == ':') ? where + " " + key : where + "." + key;
  };
  for (auto it = node.begin(); it != node.end(); ++it) {
    const std::string& key = it.key();
    if (!key.empty() && key[0] == '_') continue;
    if (!record_->asked.count({&node, key})) {
      std::string hint, best;
      std::size_t bestD = std::string::npos;
      for (const auto& [n, k] : record_->asked)
        if (n == &node && k != key) {
          const std::size_t d = editDistance(key, k);
          if (d < bestD) bestD = d, best = k;
        }
      if (!best.empty() && bestD <= std::max<std::size_t>(2, key.size() / 3)) hint = " (did you mean '" + best + "'?)";
      out.push_back(loc(key) + ": unknown key" + hint);
      continue;
    }
    const Json& v = it.value();
    if (v.is_object() && record_->visited.count(&v)) collectUnread(v, loc(key), out);
    if (v.is_array())
      for (std::size_t i = 0; i < v.size(); ++i)
        if (v[i].is_object() && record_->visited.count(&v[i]))
          collectUnread(v[i], loc(key) + "[" + std::to_string(i) + "]", out);
  }
}

std::vector<std::string> ParamReader::unreadKeys() const {
  std::vector<std::string> out;
  collectUnread(*node_, where_, out);
  return out;
}

void ParamReader::requireAllKeysRead() const {
  const auto unread = unreadKeys();
  if (unread.empty()) return;
  std::string msg;
  for (const auto& u : unread) msg += (msg.empty() ? "" : "\n") + u;
  throw Error(msg);
}

void ParamReader::markAllRead() const {
  std::function<void(const Json&)> mark = [&](const Json& n) {
    if (n.is_object()) {
      record_->visited.insert(&n);
      for (auto it = n.begin(); it != n.end(); ++it) {
        record_->asked.insert({&n, it.key()});
        mark(it.value());
      }
    } else if (n.is_array()) {
      for (const auto& e : n) mark(e);
    }
  };
  mark(*node_);
}

}  // namespace vdyn
