// Internal to src/sim: the scenario and sensor files are read through one function, so both refuse every yaml-cpp
// error (bad syntax, or a value of the wrong type such as a list where a name belongs) naming the file.
#pragma once

#include <stdexcept>
#include <string>

#include <yaml-cpp/yaml.h>

namespace ret3d {
namespace sim {

template <typename T>
T readYamlFile(const std::string& path, T (*read)(const YAML::Node& root, const std::string& path)) {
  YAML::Node root;
  try {
    root = YAML::LoadFile(path);
  } catch (const YAML::Exception& e) {
    throw std::runtime_error(path + ": cannot read YAML: " + e.what());
  }
  try {
    return read(root, path);
  } catch (const YAML::Exception& e) {
    throw std::runtime_error(path + ": " + e.what());
  }
}

}  // namespace sim
}  // namespace ret3d
