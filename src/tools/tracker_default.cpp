#include "tools/tracker_default.h"

#include <algorithm>
#include <filesystem>
#include <stdexcept>

#include <yaml-cpp/yaml.h>

namespace ret3d {
namespace tools {

std::string defaultTrackerConfig(const std::vector<std::string>& stages, const std::string& package_dir) {
  if (std::find(stages.begin(), stages.end(), "base") == stages.end()) return "";
  if (package_dir.empty())
    throw std::runtime_error(std::string("the base stage tracks with the nodelets' ") + kPipelineTrackerConfig +
                             ", but the ret3d package is not on ROS_PACKAGE_PATH (`source scripts/env.sh`); or give "
                             "--tracker-config FILE");
  const std::string path = (std::filesystem::path(package_dir) / kPipelineTrackerConfig).string();
  if (!std::filesystem::exists(path))
    throw std::runtime_error(path + ": no such file (the base stage's default tracker config); give --tracker-config FILE");
  return path;
}

double pipelineDetectorThreshold(const std::string& package_dir, double fallback) {
  const std::string path = (std::filesystem::path(package_dir) / kPipelineParams).string();
  if (package_dir.empty() || !std::filesystem::exists(path)) return fallback;
  try {
    const YAML::Node t = YAML::LoadFile(path)["ret3d_detector"]["score_threshold"];
    if (!t) return fallback;
    const double v = t.as<double>();
    if (!(v >= 0 && v <= 1)) throw std::runtime_error("must lie in [0, 1]");
    return v;
  } catch (const std::exception& e) {
    throw std::runtime_error(path + ": ret3d_detector/score_threshold: " + e.what());
  }
}

}  // namespace tools
}  // namespace ret3d
