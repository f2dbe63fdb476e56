// The ego vehicle's own body, as an axis-aligned box in its base frame (base_link: x forward, y left, z up, on the
// ground under the sensor). Returns inside it are the vehicle's own (mirrors, roof racks, the sensor mount), and no
// object can stand inside or against it: the detector drops both (as Autoware's crop-box filter drops self-returns).
#pragma once

#include <string>
#include <vector>

#include <Eigen/Geometry>

#include "ret3d/core/option_range.h"
#include "ret3d/core/types.h"

namespace ret3d {

struct EgoBox {
  // KITTI's recording car (a VW Passat estate, 4.8 x 1.8 m; its HDL-64E 1.73 m above the ground, about 2.1 m ahead of
  // the rear bumper), with some room for the mirrors: x from the rear bumper to the front, y across, z ground to roof.
  double x_min = -2.3, x_max = 2.8, y_min = -1.1, y_max = 1.1, z_min = -0.5, z_max = 2.0;

  // [x_min, x_max, y_min, y_max, z_min, z_max] as YAML, a ROS parameter or --ego-box give it. Throws OptionError
  // (key "ego_box") unless six finite numbers with each min below its max.
  static EgoBox fromValues(const std::vector<double>& values);
  std::vector<double> values() const { return {x_min, x_max, y_min, y_max, z_min, z_max}; }
  std::string describe() const;  // "[-2.3, 2.8, -1.1, 1.1, -0.5, 2]"

  bool contains(const Eigen::Vector3d& p_base) const {
    return p_base.x() >= x_min && p_base.x() <= x_max && p_base.y() >= y_min && p_base.y() <= y_max &&
           p_base.z() >= z_min && p_base.z() <= z_max;
  }
  // True when box `b` (in the sensor frame) reaches into this box grown by `margin` (m) in BEV: an object inside or
  // against the vehicle's body.
  bool touches(const Box& b, const Eigen::Isometry3d& sensor_to_base, double margin) const;
};

// The sensor's pose in base_link where nothing else says it: KITTI's HDL-64E, 1.73 m above the ground, as the bags
// ret3d writes and the simulator's presets mount it.
Eigen::Isometry3d defaultSensorToBase();

// Removes the points (and their time / ring entries) inside `ego`; returns how many were removed.
std::size_t removePointsInside(const EgoBox& ego, const Eigen::Isometry3d& sensor_to_base, PointCloud* cloud);

}  // namespace ret3d
