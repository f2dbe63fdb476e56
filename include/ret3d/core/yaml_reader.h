// The package's one reader of YAML configuration (detector, relation, tracker, simulator and sensor files). It reads
// typed values by key from a map, refuses keys nobody asked for (typos), values of the wrong type and values out of
// range, each with a message naming the file, the full key path and the reason, e.g.
//   config/tracker.yaml: key 'gate.Truck': unknown class (line 3; classes: Car, Pedestrian, Cyclist)
// An absent key leaves its value as it was, so an options struct's defaults apply to whatever a file does not set.
//
// A file may start from another: a top-level `base: other.yaml` (relative to the file) reads that file first and lays
// this one over it, maps merged key by key and any other value (a number, a list) replaced whole, so an ablation
// config holds only what it changes. A base may have a base; a cycle or a missing base file is an error naming the
// file. Line numbers in messages about such a file count lines of the merged document.
#pragma once

#include <initializer_list>
#include <limits>
#include <memory>
#include <set>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "ret3d/core/option_range.h"
#include "ret3d/core/per_class.h"
#include "ret3d/core/types.h"

namespace YAML {
class Node;
}

namespace ret3d {

// A configuration refused by YamlReader, or a file that cannot be read or parsed.
class ConfigError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// The whole text of a configuration file, its `base:` chain resolved (the merged document, without `base`);
// ConfigError "ORIGIN: cannot be read" when it cannot be, or naming the key `base` when a base is wrong.
std::string readConfigText(const std::string& file, const std::string& origin);

class YamlReader {
 public:
  static constexpr double kNoLimit = std::numeric_limits<double>::infinity();

  // The document in `text`. `origin` names it in every message (a file path, or e.g. "IntraRM config <string>");
  // `path` is the key path of the document when it is one section read alone (e.g. "model"). Bad syntax fails
  // naming the line. An empty document reads as an empty map.
  static YamlReader parse(const std::string& text, const std::string& origin, const std::string& path = "");
  // The document in `file`, named by its path, its `base:` chain resolved (readConfigText). parse() knows no
  // folder to resolve a base from: there `base` is an unknown key like any other.
  static YamlReader load(const std::string& file);

  YamlReader(YamlReader&&) noexcept;
  YamlReader& operator=(YamlReader&&) noexcept;
  ~YamlReader();

  // Reads `key` as T: bool (true or false), int, unsigned, unsigned long, float, double, std::string, or a
  // std::vector of int, double or std::string (checked element by element, key[i]). Returns false, leaving *value
  // as it was, when the key is absent.
  template <typename T>
  bool get(const std::string& key, T* value);
  // The same, and a number must lie in [lo, hi] (kNoLimit for an open end).
  template <typename T>
  bool get(const std::string& key, T* value, double lo, double hi) {
    return get(key, value, OptionRange{lo, hi});
  }
  // The same in the range an options struct keeps for the value (e.g. InferenceOptions::kScoreThreshold).
  template <typename T>
  bool get(const std::string& key, T* value, const OptionRange& range) {
    if (!get(key, value)) return false;
    within(key, static_cast<double>(*value), range);
    return true;
  }
  // One of the named `choices`, e.g. head: anchor | center.
  template <typename E>
  bool getChoice(const std::string& key, E* value, std::initializer_list<std::pair<const char*, E>> choices) {
    std::vector<std::string> names;
    for (const auto& c : choices) names.push_back(c.first);
    const int i = choiceIndex(key, names);
    if (i < 0) return false;
    *value = (choices.begin() + i)->second;
    return true;
  }
  // A list of class names, e.g. classes: [Car, Pedestrian].
  bool getClasses(const std::string& key, std::vector<ObjectClass>* value);
  // A map by class name, e.g. centroid: {Pedestrian: 0.1}: the classes it names, in document order, replace *value.
  // V: int, double or std::vector<double>.
  template <typename V>
  bool getClassValues(const std::string& key, std::vector<std::pair<ObjectClass, V>>* value);
  // The same into one value per class; the classes it does not name keep theirs.
  template <typename T>
  bool getPerClass(const std::string& key, PerClass<T>* value) {
    std::vector<std::pair<ObjectClass, T>> given;
    if (!getClassValues(key, &given)) return false;
    for (const auto& [c, v] : given) value->at(c) = v;
    return true;
  }

  // The map under `key`; absent or empty, a reader of nothing.
  YamlReader child(const std::string& key);
  // The maps listed under `key` (paths key[0], key[1], ...); none when it is absent.
  std::vector<YamlReader> children(const std::string& key);
  // The keys of this map in document order (e.g. the names of a map of materials, each then read as a child).
  std::vector<std::string> keys() const;
  bool has(const std::string& key) const;
  bool isMap(const std::string& key) const;

  // Refuses every key of this map that nothing read (a typo), naming the keys that were read.
  void finish() const;
  // Refuses v outside [lo, hi] (kNoLimit: an open end) naming `key`: the one range check of every reader.
  void within(const std::string& key, double v, double lo, double hi) const { within(key, v, OptionRange{lo, hi}); }
  void within(const std::string& key, double v, const OptionRange& range) const;
  // Throws ConfigError "ORIGIN: key 'PATH.key': REASON" ("ORIGIN: REASON" for the key "" of the document).
  [[noreturn]] void fail(const std::string& key, const std::string& reason) const;
  // The dotted path of `key` below this map, e.g. "model.bev.resolution".
  std::string fullKey(const std::string& key) const;
  const std::string& origin() const { return origin_; }

 private:
  YamlReader(const YAML::Node& node, std::string origin, std::string path);
  int choiceIndex(const std::string& key, const std::vector<std::string>& names);
  bool find(const std::string& key, YAML::Node* value) const;  // the value under `key`, if present

  std::unique_ptr<YAML::Node> node_;  // a map, or null for an absent section
  std::string origin_, path_;
  std::set<std::string> known_;
};

}  // namespace ret3d
