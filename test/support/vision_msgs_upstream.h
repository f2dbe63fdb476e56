// The md5sums of upstream vision_msgs 0.0.2 (the ROS 1 noetic release, github.com/ros-perception/vision_msgs,
// CHANGELOG 0.0.2 of 2022-04-09), as its generated code states them (gencpp's MD5Sum traits and genpy / genjs /
// rosserial output of the same release in public noetic workspaces). A message built from third_party/vision_msgs
// must carry exactly these, or nodes built against the upstream package would refuse to connect.
#pragma once

#include <string>
#include <utility>
#include <vector>

namespace ret3d {
namespace test {

inline const std::vector<std::pair<std::string, std::string>>& upstreamVisionMsgsMd5() {
  static const std::vector<std::pair<std::string, std::string>> kMd5 = {
      {"vision_msgs/Detection3DArray", "05c51d9aea1fb4cfdc8effb94f197b6f"},
      {"vision_msgs/Detection3D", "7f3d8e29f3ab9853108801543aec1a5d"},
      {"vision_msgs/ObjectHypothesisWithPose", "fa1ab3bc7146f53921fa142d631d02db"},
      {"vision_msgs/BoundingBox3D", "727c83f2b037373b8e968433d9c84ecb"},
  };
  return kMd5;
}

}  // namespace test
}  // namespace ret3d
