#include "ret3d/core/yaml_reader.h"

#include <filesystem>
#include <fstream>
#include <sstream>
#include <vector>

#include <yaml-cpp/yaml.h>

namespace ret3d {
namespace {

[[noreturn]] void refuse(const std::string& origin, const std::string& key, const std::string& reason) {
  throw ConfigError(key.empty() ? origin + ": " + reason : origin + ": key '" + key + "': " + reason);
}

std::string lineOf(const YAML::Node& n) { return "line " + std::to_string(n.Mark().line + 1); }

// A value on one line: abc, [1, 2], {a: 1} (yaml-cpp's emitter keeps a block list from the file in block style).
std::string flow(const YAML::Node& n) {
  if (n.IsScalar()) return n.Scalar();
  if (!n.IsSequence() && !n.IsMap()) return "~";
  std::string s;
  for (const auto& item : n) {
    s += s.empty() ? "" : ", ";
    s += n.IsMap() ? flow(item.first) + ": " + flow(item.second) : flow(item);
  }
  return n.IsMap() ? "{" + s + "}" : "[" + s + "]";
}

// A value as a message shows it: 'abc', [1, 2], {a: 1}.
std::string shown(const YAML::Node& n) {
  if (n.IsScalar()) return "'" + n.Scalar() + "'";
  if (n.IsNull()) return "nothing";
  const std::string s = flow(n);
  return s.size() > 60 ? s.substr(0, 57) + "..." : s;
}

// What a value of a type must be, for messages ("a number", or "numbers" when `many`).
std::string expected(const bool*, bool many) { return many ? "true or false values" : "true or false"; }
std::string expected(const int*, bool many) { return many ? "integers" : "an integer"; }
std::string expected(const unsigned*, bool many) { return many ? "integers >= 0" : "an integer >= 0"; }
std::string expected(const unsigned long*, bool many) { return many ? "integers >= 0" : "an integer >= 0"; }
std::string expected(const float*, bool many) { return many ? "numbers" : "a number"; }
std::string expected(const double*, bool many) { return many ? "numbers" : "a number"; }
std::string expected(const std::string*, bool many) { return many ? "strings" : "a string"; }
template <typename T>
std::string expected(const std::vector<T>*, bool many) {
  return (many ? "lists of " : "a list of ") + expected(static_cast<const T*>(nullptr), true);
}

template <typename T>
void convert(const YAML::Node& n, T* out, const std::string& origin, const std::string& key) {
  T v;
  if (!YAML::convert<T>::decode(n, v))
    refuse(origin, key, "expected " + expected(out, false) + ", not " + shown(n) + " (" + lineOf(n) + ")");
  *out = std::move(v);
}

// Element by element, so a message names the element (key[i]) that is wrong.
template <typename T>
void convert(const YAML::Node& n, std::vector<T>* out, const std::string& origin, const std::string& key) {
  if (!n.IsSequence())
    refuse(origin, key, "expected " + expected(out, false) + ", not " + shown(n) + " (" + lineOf(n) + ")");
  std::vector<T> v(n.size());
  for (std::size_t i = 0; i < n.size(); ++i) convert(n[i], &v[i], origin, key + "[" + std::to_string(i) + "]");
  *out = std::move(v);
}

// A key of a map as text; a key that is not a plain name (a list, a map) is refused.
std::string keyText(const YAML::Node& key, const std::string& origin, const std::string& map_path) {
  if (!key.IsScalar()) refuse(origin, map_path, "a key (" + lineOf(key) + ") is not a plain name");
  return key.Scalar();
}

std::string joined(const std::vector<std::string>& names, const char* last) {
  std::string s;
  for (std::size_t i = 0; i < names.size(); ++i)
    s += (i == 0 ? "" : i + 1 == names.size() ? last : ", ") + names[i];
  return s;
}

const char* const kClassList = "Car, Pedestrian, Cyclist";

}  // namespace

namespace {

std::string readWholeFile(const std::string& file, const std::string& origin) {
  std::ifstream in(file);
  std::error_code ec;
  if (!in || std::filesystem::is_directory(file, ec)) throw ConfigError(origin + ": cannot be read");
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

// `over` laid over `base`: maps key by key (recursively), anything else (a number, a list) replaced whole.
YAML::Node merged(const YAML::Node& base, const YAML::Node& over) {
  if (!base.IsMap() || !over.IsMap()) return YAML::Clone(over);
  YAML::Node out = YAML::Clone(base);
  for (const auto& kv : over) {
    const std::string key = kv.first.Scalar();
    YAML::Node existing;
    for (const auto& b : out)
      if (b.first.IsScalar() && b.first.Scalar() == key) existing.reset(b.second);
    out[key] = existing.IsDefined() ? merged(existing, kv.second) : YAML::Clone(kv.second);
  }
  return out;
}

// The document of `file` with its `base:` chain resolved; `chain` holds the files that include it (cycle check).
// Returns an undefined node when the file has no `base:` (its text is then used as it is, line numbers intact).
YAML::Node resolveBase(const std::string& file, const std::string& origin, std::vector<std::string>* chain) {
  const std::string text = readWholeFile(file, origin);
  YAML::Node doc;
  try {
    doc = YAML::Load(text);
  } catch (const YAML::Exception&) {
    if (chain->empty()) return YAML::Node(YAML::NodeType::Undefined);  // parse() reports it, with its line
    throw ConfigError(origin + ": included as a base by " + chain->back() + ": not valid YAML");
  }
  const YAML::Node& const_doc = doc;  // the const operator[] looks a key up without adding it
  if (!doc.IsMap() || !const_doc["base"]) return chain->empty() ? YAML::Node(YAML::NodeType::Undefined) : doc;
  const YAML::Node base_key = const_doc["base"];
  if (!base_key.IsScalar() || base_key.Scalar().empty())
    refuse(origin, "base", "expected the path of a base file (relative to this file), not " + shown(base_key) + " (" +
                               lineOf(base_key) + ")");
  std::filesystem::path base_path(base_key.Scalar());
  if (base_path.is_relative()) base_path = std::filesystem::path(file).parent_path() / base_path;
  const std::string base_file = base_path.lexically_normal().string();
  std::error_code ec;
  const std::string canonical = std::filesystem::weakly_canonical(file, ec).string();
  chain->push_back(canonical.empty() ? file : canonical);
  const std::string base_canonical = std::filesystem::weakly_canonical(base_file, ec).string();
  for (const std::string& f : *chain) {
    if (f != base_canonical) continue;
    std::string cycle;
    for (const std::string& g : *chain) cycle += g + " -> ";
    refuse(origin, "base", "the bases form a cycle: " + cycle + base_canonical);
  }
  if (!std::filesystem::exists(base_file, ec))
    refuse(origin, "base", "the base file '" + base_file + "' does not exist (" + lineOf(base_key) + ")");
  YAML::Node base = resolveBase(base_file, base_file, chain);
  chain->pop_back();
  if (!base.IsNull() && !base.IsMap())
    throw ConfigError(base_file + ": a base file must hold a map (included by " + file + ")");
  YAML::Node over = YAML::Clone(doc);
  over.remove("base");
  return base.IsNull() ? over : merged(base, over);
}

}  // namespace

std::string readConfigText(const std::string& file, const std::string& origin) {
  std::vector<std::string> chain;
  const YAML::Node resolved = resolveBase(file, origin, &chain);
  if (!resolved.IsDefined()) return readWholeFile(file, origin);
  YAML::Emitter e;
  e << resolved;
  return std::string(e.c_str()) + "\n";
}

YamlReader::YamlReader(const YAML::Node& node, std::string origin, std::string path)
    : node_(std::make_unique<YAML::Node>(node)), origin_(std::move(origin)), path_(std::move(path)) {
  if (node_->IsDefined() && !node_->IsNull() && !node_->IsMap())
    refuse(origin_, path_, "expected a map, not " + shown(*node_) + " (" + lineOf(*node_) + ")");
}

YamlReader::YamlReader(YamlReader&&) noexcept = default;
YamlReader& YamlReader::operator=(YamlReader&&) noexcept = default;
YamlReader::~YamlReader() = default;

YamlReader YamlReader::parse(const std::string& text, const std::string& origin, const std::string& path) {
  try {
    return YamlReader(YAML::Load(text), origin, path);
  } catch (const YAML::Exception& e) {
    refuse(origin, "", "not valid YAML: line " + std::to_string(e.mark.line + 1) + ", column " +
                           std::to_string(e.mark.column + 1) + ": " + e.msg);
  }
}

YamlReader YamlReader::load(const std::string& file) { return parse(readConfigText(file, file), file); }

std::string YamlReader::fullKey(const std::string& key) const {
  return path_.empty() ? key : key.empty() ? path_ : path_ + "." + key;
}

void YamlReader::fail(const std::string& key, const std::string& reason) const {
  refuse(origin_, fullKey(key), reason);
}

// By iteration, not operator[]: yaml-cpp's non-const operator[] would turn a node into a map.
bool YamlReader::find(const std::string& key, YAML::Node* value) const {
  if (!node_->IsMap()) return false;
  for (const auto& kv : *node_) {
    if (kv.first.IsScalar() && kv.first.Scalar() == key) {
      value->reset(kv.second);  // rebinds; operator= would write into the node it refers to
      return true;
    }
  }
  return false;
}

bool YamlReader::has(const std::string& key) const {
  YAML::Node n;
  return find(key, &n);
}

bool YamlReader::isMap(const std::string& key) const {
  YAML::Node n;
  return find(key, &n) && n.IsMap();
}

template <typename T>
bool YamlReader::get(const std::string& key, T* value) {
  known_.insert(key);
  YAML::Node n;
  if (!find(key, &n)) return false;
  convert(n, value, origin_, fullKey(key));
  return true;
}

template bool YamlReader::get(const std::string&, bool*);
template bool YamlReader::get(const std::string&, int*);
template bool YamlReader::get(const std::string&, unsigned*);
template bool YamlReader::get(const std::string&, unsigned long*);
template bool YamlReader::get(const std::string&, float*);
template bool YamlReader::get(const std::string&, double*);
template bool YamlReader::get(const std::string&, std::string*);
template bool YamlReader::get(const std::string&, std::vector<int>*);
template bool YamlReader::get(const std::string&, std::vector<double>*);
template bool YamlReader::get(const std::string&, std::vector<std::string>*);

int YamlReader::choiceIndex(const std::string& key, const std::vector<std::string>& names) {
  std::string name;
  if (!get(key, &name)) return -1;
  for (std::size_t i = 0; i < names.size(); ++i)
    if (names[i] == name) return static_cast<int>(i);
  fail(key, "must be " + joined(names, " or ") + ", not '" + name + "'");
}

bool YamlReader::getClasses(const std::string& key, std::vector<ObjectClass>* value) {
  std::vector<std::string> names;
  if (!get(key, &names)) return false;
  std::vector<ObjectClass> classes;
  for (std::size_t i = 0; i < names.size(); ++i) {
    const auto c = classFromName(names[i]);
    if (!c) fail(key + "[" + std::to_string(i) + "]", "unknown class '" + names[i] + "' (" + kClassList + ")");
    classes.push_back(*c);
  }
  *value = std::move(classes);
  return true;
}

template <typename V>
bool YamlReader::getClassValues(const std::string& key, std::vector<std::pair<ObjectClass, V>>* value) {
  known_.insert(key);
  YAML::Node n;
  if (!find(key, &n)) return false;
  const std::string path = fullKey(key);
  if (!n.IsMap())
    refuse(origin_, path, std::string("expected a map from class names (") + kClassList + ") to " +
                              expected(static_cast<const V*>(nullptr), true) + ", not " + shown(n) + " (" +
                              lineOf(n) + ")");
  std::vector<std::pair<ObjectClass, V>> given;
  for (const auto& kv : n) {
    const std::string name = keyText(kv.first, origin_, path);
    const auto c = classFromName(name);
    if (!c) refuse(origin_, path + "." + name, "unknown class (" + lineOf(kv.first) + "; classes: " + kClassList + ")");
    V v;
    convert(kv.second, &v, origin_, path + "." + name);
    given.emplace_back(*c, std::move(v));
  }
  *value = std::move(given);
  return true;
}

template bool YamlReader::getClassValues(const std::string&, std::vector<std::pair<ObjectClass, int>>*);
template bool YamlReader::getClassValues(const std::string&, std::vector<std::pair<ObjectClass, double>>*);
template bool YamlReader::getClassValues(const std::string&, std::vector<std::pair<ObjectClass, std::vector<double>>>*);

YamlReader YamlReader::child(const std::string& key) {
  known_.insert(key);
  YAML::Node n;
  find(key, &n);
  return YamlReader(n, origin_, fullKey(key));
}

std::vector<YamlReader> YamlReader::children(const std::string& key) {
  known_.insert(key);
  std::vector<YamlReader> out;
  YAML::Node n;
  if (!find(key, &n)) return out;
  if (!n.IsSequence()) fail(key, "expected a list of maps, not " + shown(n) + " (" + lineOf(n) + ")");
  for (std::size_t i = 0; i < n.size(); ++i)
    out.push_back(YamlReader(n[i], origin_, fullKey(key) + "[" + std::to_string(i) + "]"));
  return out;
}

std::vector<std::string> YamlReader::keys() const {
  std::vector<std::string> out;
  if (node_->IsMap())
    for (const auto& kv : *node_) out.push_back(keyText(kv.first, origin_, path_));
  return out;
}

void YamlReader::finish() const {
  if (!node_->IsMap()) return;
  for (const auto& kv : *node_) {
    const std::string key = keyText(kv.first, origin_, path_);
    if (known_.count(key)) continue;
    const std::vector<std::string> names(known_.begin(), known_.end());
    fail(key, "unknown key (" + lineOf(kv.first) + "; known keys: " + (names.empty() ? "none" : joined(names, ", ")) +
                  ")");
  }
}

void YamlReader::within(const std::string& key, double v, const OptionRange& range) const {
  if (!range.contains(v)) fail(key, range.describe() + ", got " + optionValueText(v));
}

}  // namespace ret3d
