#include "ret3d/pipeline/tracker_default.h"

#include <algorithm>
#include <filesystem>
#include <stdexcept>

namespace ret3d {
namespace pipeline {

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

}  // namespace pipeline
}  // namespace ret3d
