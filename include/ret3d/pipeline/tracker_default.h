// The tracker configuration the offline pipeline (`ret3d detect`, `bench`, `autolabel`) runs when --tracker-config is
// not given: the same as the nodelets wherever the scores are the same.
#pragma once

#include <string>
#include <vector>

namespace ret3d {
namespace pipeline {

// The tracker YAML of the LWD-3D pipeline, relative to the package (config/ret3d.yaml names it for the nodelets): the
// one constant for that path outside the parameter file.
inline constexpr const char* kPipelineTrackerConfig = "config/tracker_lwd3d_pipeline.yaml";

// With the base stage (the LWD-3D detector, whose scores are probabilities): <package_dir>/kPipelineTrackerConfig,
// as online. Without it (another detector's boxes, e.g. PointRCNN's logits): "", TrackerOptions' built-in values,
// which are tuned for those. Throws, saying what to do, when the base stage needs the file and package_dir is empty
// (the package is not on ROS_PACKAGE_PATH) or the file is missing.
std::string defaultTrackerConfig(const std::vector<std::string>& stages, const std::string& package_dir);

}  // namespace pipeline
}  // namespace ret3d
