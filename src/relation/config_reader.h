// Internal to src/relation: the YAML field reading shared by the IntraRM and InterRM config loaders, so both refuse
// typos, wrong types and unknown classes with the same messages ("<What> config SOURCE: ...").
#pragma once

#include <array>
#include <fstream>
#include <set>
#include <sstream>
#include <stdexcept>
#include <string>

#include <yaml-cpp/yaml.h>

#include "ret3d/core/types.h"

namespace ret3d {
namespace relation {
namespace detail {

class ConfigReader {
 public:
  // what: "IntraRM" or "InterRM"; source: the file name (or another label) used in messages.
  ConfigReader(std::string what, std::string source) : what_(std::move(what)), source_(std::move(source)) {}

  [[noreturn]] void fail(const std::string& problem) const {
    throw std::invalid_argument(what_ + " config " + source_ + ": " + problem);
  }

  // The parsed document; a YAML syntax error fails like any other bad value.
  YAML::Node load(const std::string& yaml_text) const {
    try {
      return YAML::Load(yaml_text);
    } catch (const YAML::Exception& e) {
      fail(std::string("not valid YAML: ") + e.what());
    }
  }

  void checkKeys(const YAML::Node& node, const std::set<std::string>& allowed, const std::string& section) const {
    if (!node.IsMap()) fail("'" + section + "' must be a mapping");
    for (const auto& kv : node) {
      const std::string key = keyName(kv.first, section);
      if (!allowed.count(key)) {
        std::string list;
        for (const auto& a : allowed) list += (list.empty() ? "" : ", ") + a;
        fail("unknown key '" + section + "." + key + "' (line " + std::to_string(kv.first.Mark().line + 1) +
             "; known: " + list + ")");
      }
    }
  }

  // A mapping key as text; a key that is not a plain scalar (a sequence, a null) fails naming the line.
  std::string keyName(const YAML::Node& key, const std::string& section) const {
    if (!key.IsScalar())
      fail("a key of '" + section + "' (line " + std::to_string(key.Mark().line + 1) + ") is not a plain name");
    return key.Scalar();
  }

  // Leaves *value unchanged when the key is absent.
  template <typename T>
  void read(const YAML::Node& node, const char* key, T* value, const std::string& section) const {
    if (!node[key]) return;
    try {
      *value = node[key].as<T>();
    } catch (const YAML::Exception&) {
      fail("'" + section + "." + key + "' (line " + std::to_string(node[key].Mark().line + 1) +
           ") is not a valid value");
    }
  }

  // A map Car/Pedestrian/Cyclist -> number into a per-class array (index = label - 1).
  void readPerClass(const YAML::Node& node, const char* key, std::array<double, 3>* value,
                    const std::string& section) const {
    if (!node[key]) return;
    const YAML::Node n = node[key];
    const std::string name = "'" + section + "." + key;
    if (!n.IsMap()) fail(name + "' must map Car/Pedestrian/Cyclist to numbers");
    for (const auto& kv : n) {
      const std::string cls_name = keyName(kv.first, section + "." + key);
      const auto cls = classFromName(cls_name);
      if (!cls) fail(name + "' has unknown class '" + cls_name + "'");
      try {
        (*value)[static_cast<int>(*cls) - 1] = kv.second.as<double>();
      } catch (const YAML::Exception&) {
        fail(name + "." + cls_name + "' is not a number");
      }
    }
  }

 private:
  std::string what_;
  std::string source_;
};

// The whole text of a config file; a std::runtime_error naming it when it cannot be read.
inline std::string readConfigFile(const std::string& what, const std::string& path) {
  std::ifstream in(path);
  if (!in) throw std::runtime_error(what + " config " + path + ": cannot be read");
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

}  // namespace detail
}  // namespace relation
}  // namespace ret3d
