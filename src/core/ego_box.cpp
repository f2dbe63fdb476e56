#include "ret3d/core/ego_box.h"

#include <cmath>
#include <sstream>

#include "ret3d/core/geometry.h"

namespace ret3d {

EgoBox EgoBox::fromValues(const std::vector<double>& v) {
  std::ostringstream text;
  text << "[";
  for (std::size_t i = 0; i < v.size(); ++i) text << (i ? ", " : "") << optionValueText(v[i]);
  text << "]";
  if (v.size() != 6) throw OptionError("ego_box", text.str(), "needs six numbers [x_min, x_max, y_min, y_max, z_min, z_max]");
  for (double x : v)
    if (!std::isfinite(x)) throw OptionError("ego_box", text.str(), "needs finite numbers");
  if (!(v[0] < v[1] && v[2] < v[3] && v[4] < v[5]))
    throw OptionError("ego_box", text.str(), "each minimum must lie below its maximum");
  return EgoBox{v[0], v[1], v[2], v[3], v[4], v[5]};
}

std::string EgoBox::describe() const {
  std::ostringstream os;
  const std::vector<double> v = values();
  os << "[";
  for (std::size_t i = 0; i < v.size(); ++i) os << (i ? ", " : "") << optionValueText(v[i]);
  os << "]";
  return os.str();
}

bool EgoBox::touches(const Box& b, const Eigen::Isometry3d& sensor_to_base, double margin) const {
  // The box's footprint in base_link (yaw about the base's z; a tilted mount changes the footprint only slightly).
  const Eigen::Vector3d c = sensor_to_base * b.center();
  const Eigen::Vector3d heading = sensor_to_base.linear() * Eigen::Vector3d(std::cos(b.yaw), std::sin(b.yaw), 0);
  Box in_base = b;
  in_base.x = c.x(), in_base.y = c.y(), in_base.z = c.z();
  in_base.yaw = std::atan2(heading.y(), heading.x());
  Box body;
  body.x = 0.5 * (x_min + x_max), body.y = 0.5 * (y_min + y_max), body.z = 0.5 * (z_min + z_max);
  body.length = x_max - x_min + 2 * margin, body.width = y_max - y_min + 2 * margin, body.height = z_max - z_min;
  body.yaw = 0;
  return bevIntersectionArea(in_base, body) > 0;
}

Eigen::Isometry3d defaultSensorToBase() { return Eigen::Isometry3d(Eigen::Translation3d(0, 0, 1.73)); }

std::size_t removePointsInside(const EgoBox& ego, const Eigen::Isometry3d& sensor_to_base, PointCloud* cloud) {
  const bool time = cloud->hasTime(), ring = cloud->hasRing();
  std::size_t kept = 0;
  for (std::size_t i = 0; i < cloud->points.size(); ++i) {
    const Point& p = cloud->points[i];
    if (ego.contains(sensor_to_base * Eigen::Vector3d(p.x, p.y, p.z))) continue;
    cloud->points[kept] = p;
    if (time) cloud->time[kept] = cloud->time[i];
    if (ring) cloud->ring[kept] = cloud->ring[i];
    ++kept;
  }
  const std::size_t removed = cloud->points.size() - kept;
  cloud->points.resize(kept);
  if (time) cloud->time.resize(kept);
  if (ring) cloud->ring.resize(kept);
  return removed;
}

}  // namespace ret3d
