// rviz markers for the pipeline's objects: oriented box edges coloured by class, a text label (class, track id,
// score), a velocity arrow and a short trail of each track's past centres. Every array starts with DELETEALL, so
// nothing from an earlier frame stays on screen.
//
// Class colours (saturated, distinct from the greyscale intensity cloud of rviz/ret3d.rviz; the rviz test looks for
// them): Car green (0, 255, 0), Pedestrian magenta (255, 0, 255), Cyclist orange (255, 160, 0); Unknown grey.
#pragma once

#include <std_msgs/Header.h>
#include <visualization_msgs/MarkerArray.h>

#include <array>
#include <cstdint>
#include <deque>
#include <unordered_map>
#include <vector>

#include <Eigen/Geometry>

#include "ret3d/core/option_range.h"
#include "ret3d/core/types.h"

namespace ret3d {

struct MarkerOptions {
  int trail_length = 10;        // past centres per track (1 s at 10 Hz); 0 = no trails
  double line_width = 0.08;     // m, box edges and trails
  double text_size = 0.8;       // m, label height
  double min_arrow_speed = 0.3; // m/s: slower objects get no velocity arrow
  double arrow_seconds = 1.0;   // the arrow shows where the object is this many seconds later

  // Ranges (core/option_range.h), read by the marker nodelet's parameters (ros/params.cpp).
  static constexpr OptionRange kTrailLength{0, 1000};
  static constexpr OptionRange kLineWidth{0.001, 10.0};
  static constexpr OptionRange kTextSize{0.01, 100.0};
  static constexpr OptionRange kMinArrowSpeed{0.0, 1000.0};
  static constexpr OptionRange kArrowSeconds{0.0, 100.0};
};

// RGB in [0, 1].
std::array<float, 3> classColour(ObjectClass c);

// Builds one MarkerArray per frame; keeps the trails between frames.
class MarkerBuilder {
 public:
  explicit MarkerBuilder(const MarkerOptions& options = {}) : options_(options) {}

  // Markers for `boxes` (in header.frame_id at header.stamp) whose sensor pose in the fixed frame is sensor_to_fixed
  // (trails are kept in the fixed frame and drawn in the current sensor frame, so they stay put while the vehicle
  // moves). A stamp before the previous one (a bag loop) clears the trails.
  visualization_msgs::MarkerArray build(const std::vector<Box>& boxes, const std_msgs::Header& header,
                                        const Eigen::Isometry3d& sensor_to_fixed = Eigen::Isometry3d::Identity());

  std::size_t numTrails() const { return trails_.size(); }

 private:
  struct Trail {
    std::deque<Eigen::Vector3d> centres;  // fixed frame, oldest first
    std::uint64_t last_frame = 0;
  };
  MarkerOptions options_;
  std::unordered_map<std::uint32_t, Trail> trails_;
  std::uint64_t frame_ = 0;
  double last_stamp_ = -1.0;
};

}  // namespace ret3d
