#include "vdyn/core/key_path.h"

#include <algorithm>
#include <cctype>

#include "vdyn/core/error.h"

namespace vdyn {

namespace {
bool isIndex(const std::string& t) {
  if (t.empty() || t.size() > 9) return false;
  for (char c : t)
    if (c < '0' || c > '9') return false;
  return true;
}

/// The one error form: "<where>: key path '<path>': <what>".
[[noreturn]] void fail(const std::string& where, const std::string& path, const std::string& what) {
  throw Error((where.empty() ? "" : where + ": ") + "key path '" + path + "': " + what);
}

/// Text of parts [0, n) of `parts` ("the document" when n is 0): what the
/// error names as the place where the walk stopped.
std::string prefixText(const std::vector<KeyPath::Part>& parts, std::size_t n) {
  if (n == 0) return "the document";
  std::string s;
  for (std::size_t i = 0; i < n; ++i)
    s += parts[i].bracketed ? "[" + parts[i].text + "]" : (i ? "." : "") + parts[i].text;
  return s;
}

std::string shortDump(const Json& j) {
  std::string s = j.dump();
  return s.size() > 60 ? s.substr(0, 57) + "..." : s;
}

/// One step of a walk from `node` at part i of `parts`: the child and how
/// many parts it used (keys holding dots use several), or nullptr with `why`
/// saying what was found instead.
template <class J>
J* step(J* node, const std::vector<KeyPath::Part>& parts, std::size_t i, std::size_t& used, std::string& why) {
  const KeyPath::Part& p = parts[i];
  used = 1;
  if (node->is_array()) {
    if (p.bracketed || isIndex(p.text)) {
      const std::size_t k = std::stoul(p.text);
      if (k < node->size()) return &(*node)[k];
      why = prefixText(parts, i) + " has " + std::to_string(node->size()) + " elements, no [" + p.text + "]";
      return nullptr;
    }
    for (auto& e : *node)
      if (e.is_object() && e.contains("name") && e["name"] == p.text) return &e;
    why = prefixText(parts, i) + " has no element named '" + p.text + "'";
    return nullptr;
  }
  if (node->is_object() && !p.bracketed) {
    // The longest run of plain parts that is one key wins.
    std::size_t last = i;
    while (last + 1 < parts.size() && !parts[last + 1].bracketed) ++last;
    for (std::size_t e = last + 1; e > i; --e) {
      std::string key = parts[i].text;
      for (std::size_t k = i + 1; k < e; ++k) key += "." + parts[k].text;
      auto it = node->find(key);
      if (it != node->end()) {
        used = e - i;
        return &*it;
      }
    }
    why = prefixText(parts, i) + " has no key '" + p.text + "'";
    return nullptr;
  }
  if (node->is_object())
    why = prefixText(parts, i) + " is an object, not an array: no [" + p.text + "]";
  else
    why = prefixText(parts, i) + " is " + shortDump(*node) + ", not an object or array";
  return nullptr;
}
}  // namespace

KeyPath KeyPath::parse(const std::string& text, const std::string& where) {
  auto bad = [&](const std::string& why) { fail(where, text, why + " (expected e.g. a.b[2].c)"); };
  if (text.empty()) bad("empty");
  std::vector<Part> parts;
  std::string item;
  bool afterIndex = false;  // just closed "[n]": a '.', '[' or the end must follow
  for (std::size_t i = 0; i < text.size(); ++i) {
    const char c = text[i];
    if (std::isalnum(static_cast<unsigned char>(c)) || c == '_' || c == '-') {
      if (afterIndex) bad("text after an index");
      item += c;
    } else if (c == '.') {
      if (!afterIndex) {
        if (item.empty()) bad("empty part");
        parts.push_back({item, false});
        item.clear();
      }
      afterIndex = false;
      if (i + 1 == text.size()) bad("ends with '.'");
    } else if (c == '[') {
      if (!afterIndex) {
        if (item.empty()) bad("an index must follow a key");
        parts.push_back({item, false});
        item.clear();
      }
      const std::size_t close = text.find(']', i);
      if (close == std::string::npos || close == i + 1) bad("unclosed or empty index");
      const std::string index = text.substr(i + 1, close - i - 1);
      if (!isIndex(index)) bad("index [" + index + "] is not a number");
      parts.push_back({index, true});
      i = close;
      afterIndex = true;
    } else {
      bad(std::string("character '") + c + "'");
    }
  }
  if (!afterIndex) parts.push_back({item, false});
  return KeyPath(std::move(parts));
}

KeyPath KeyPath::ofKeys(const std::vector<std::string>& keys) {
  std::vector<Part> parts;
  for (const auto& k : keys) parts.push_back({k, false});
  return KeyPath(std::move(parts));
}

std::string KeyPath::format() const { return parts_.empty() ? "" : prefixText(parts_, parts_.size()); }

KeyPath KeyPath::child(const std::string& key) const {
  KeyPath k = *this;
  k.parts_.push_back({key, false});
  return k;
}

bool KeyPath::startsWith(const KeyPath& prefix) const {
  if (prefix.parts_.size() > parts_.size()) return false;
  for (std::size_t i = 0; i < prefix.parts_.size(); ++i)
    if (!(parts_[i] == prefix.parts_[i])) return false;
  return true;
}

KeyPath KeyPath::tail(std::size_t n) const {
  return KeyPath(std::vector<Part>(parts_.begin() + std::min(n, parts_.size()), parts_.end()));
}

KeyPath KeyPath::under(const KeyPath& prefix) const {
  std::vector<Part> p = prefix.parts_;
  p.insert(p.end(), parts_.begin(), parts_.end());
  return KeyPath(std::move(p));
}

const Json* KeyPath::find(const Json& j) const {
  const Json* node = &j;
  std::string why;
  for (std::size_t i = 0, used = 0; i < parts_.size(); i += used)
    if (!(node = step(node, parts_, i, used, why))) return nullptr;
  return node;
}

const Json& KeyPath::get(const Json& j, const std::string& where) const {
  const Json* node = &j;
  std::string why;
  for (std::size_t i = 0, used = 0; i < parts_.size(); i += used)
    if (!(node = step(node, parts_, i, used, why))) fail(where, format(), why);
  return *node;
}

void KeyPath::set(Json& j, Json value, const std::string& where) const {
  if (parts_.empty()) fail(where, "", "empty (expected e.g. a.b[2].c)");
  Json* node = &j;
  for (std::size_t i = 0, used = 0; i < parts_.size(); i += used) {
    if (node->is_null() && !parts_[i].bracketed) *node = Json::object();
    std::string why;
    Json* next = step(node, parts_, i, used, why);
    if (!next) {
      if (!node->is_object() || parts_[i].bracketed) fail(where, format(), why);
      next = &(*node)[parts_[i].text];  // a missing key: created
      used = 1;
    }
    node = next;
  }
  *node = std::move(value);
}

}  // namespace vdyn
