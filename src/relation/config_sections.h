// Internal to src/relation: the IntraRM and InterRM configs are both a `model:` and a `train:` section, validated
// after reading, and refused with std::invalid_argument (their documented error type) naming the file and key.
#pragma once

#include <stdexcept>
#include <string>

#include "ret3d/core/yaml_reader.h"

namespace ret3d {
namespace relation {
namespace detail {

// what: "IntraRM" or "InterRM"; read(model, train, &config) reads the keys of the two sections.
template <typename Config, typename ReadSections>
Config readConfigSections(const std::string& what, const std::string& yaml_text, const std::string& source,
                          ReadSections read) {
  Config c;
  try {
    YamlReader r = YamlReader::parse(yaml_text, what + " config " + source);
    YamlReader model = r.child("model"), train = r.child("train");
    read(model, train, &c);
    model.finish();
    train.finish();
    r.finish();
    try {
      c.model.validate();
      c.train.validate();
    } catch (const std::invalid_argument& e) {
      r.fail("", e.what());
    }
  } catch (const ConfigError& e) {
    throw std::invalid_argument(e.what());
  }
  return c;
}

}  // namespace detail
}  // namespace relation
}  // namespace ret3d
