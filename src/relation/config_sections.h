// Internal to src/relation: the IntraRM and InterRM configs are both a `model:` and a `train:` section. Each module
// lists its keys once, in `visitConfig(io, config)`: io.section("model", "hidden", &c->model.hidden, ...) and the
// same for "train", a name and a pointer per key (a PerClass<double> is read as a map by class name, an enum as
// Choice); the reader and the writer below walk that list. Reading validates after, and refuses with
// std::invalid_argument (the configs' documented error type) naming the file and key.
#pragma once

#include <initializer_list>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include <yaml-cpp/yaml.h>

#include "ret3d/core/per_class.h"
#include "ret3d/core/types.h"
#include "ret3d/core/yaml_reader.h"
#include "ret3d/relation/relation_module.h"

namespace ret3d {
namespace relation {
namespace detail {

// An enum key: its value and the names it is written as.
template <typename E>
struct Choice {
  E* value;
  std::initializer_list<std::pair<const char*, E>> names;
};

// Walks the name/pointer pairs of a section, handing each to Derived::key.
template <typename Derived>
class ConfigSections {
 public:
  template <typename... Keys>
  void section(const std::string& name, Keys... keys) {
    Derived& self = static_cast<Derived&>(*this);
    self.begin(name);
    each(self, keys...);
  }

 private:
  static void each(Derived&) {}
  template <typename T, typename... Rest>
  static void each(Derived& self, const char* name, T value, Rest... rest) {
    self.key(name, value);
    each(self, rest...);
  }
};

class ConfigSectionReader : public ConfigSections<ConfigSectionReader> {
 public:
  explicit ConfigSectionReader(YamlReader* doc) : doc_(doc) {}
  void begin(const std::string& name) { sections_.push_back(doc_->child(name)); }
  template <typename T>
  void key(const char* name, T* value) { sections_.back().get(name, value); }
  void key(const char* name, PerClass<double>* value) { sections_.back().getPerClass(name, value); }
  template <typename E>
  void key(const char* name, Choice<E> c) { sections_.back().getChoice(name, c.value, c.names); }
  // Refuses the keys nobody read (typos), section by section.
  void finish() const {
    for (const YamlReader& s : sections_) s.finish();
  }

 private:
  YamlReader* doc_;
  std::vector<YamlReader> sections_;
};

class ConfigSectionWriter : public ConfigSections<ConfigSectionWriter> {
 public:
  ConfigSectionWriter() { e_ << YAML::BeginMap; }
  void begin(const std::string& name) {
    if (open_) e_ << YAML::EndMap;
    e_ << YAML::Key << name << YAML::Value << YAML::BeginMap;
    open_ = true;
  }
  template <typename T>
  void key(const char* name, T* value) { e_ << YAML::Key << name << YAML::Value << *value; }
  void key(const char* name, PerClass<double>* value) {
    e_ << YAML::Key << name << YAML::Value << YAML::Flow << YAML::BeginMap;
    for (ObjectClass c : kDetectedClasses) e_ << YAML::Key << className(c) << YAML::Value << value->at(c);
    e_ << YAML::EndMap;
  }
  template <typename E>
  void key(const char* name, Choice<E> c) {
    for (const auto& [text, value] : c.names)
      if (value == *c.value) e_ << YAML::Key << name << YAML::Value << text;
  }
  std::string text() {
    if (open_) e_ << YAML::EndMap;
    e_ << YAML::EndMap;
    open_ = false;
    return e_.c_str();
  }

 private:
  YAML::Emitter e_;
  bool open_ = false;
};

// what: "IntraRM" or "InterRM".
template <typename Config>
Config readConfig(const std::string& what, const std::string& yaml_text, const std::string& source) {
  Config c;
  try {
    YamlReader r = YamlReader::parse(yaml_text, what + " config " + source);
    ConfigSectionReader sections(&r);
    visitConfig(sections, &c);
    sections.finish();
    r.finish();
    try {
      c.model.validate();
    } catch (const OptionError& e) {
      r.fail("model." + e.key(), e.reason() + ", got " + e.value());
    }
    try {
      c.train.validate();
    } catch (const OptionError& e) {
      r.fail("train." + e.key(), e.reason() + ", got " + e.value());
    }
  } catch (const ConfigError& e) {
    throw std::invalid_argument(e.what());
  }
  return c;
}

}  // namespace detail

// Reads the file at `path` with `parse` (the module's parse function); what: "IntraRM" or "InterRM".
template <typename Parse>
auto loadConfig(Parse parse, const std::string& what, const std::string& path) {
  return parse(readConfigText(path, what + " config " + path), path);
}

template <class Arch, class Train>
std::string toYaml(const RelationConfig<Arch, Train>& config) {
  RelationConfig<Arch, Train> c = config;  // the visit takes pointers to the fields; the writer only reads them
  detail::ConfigSectionWriter w;
  visitConfig(w, &c);
  return w.text();
}

}  // namespace relation
}  // namespace ret3d
