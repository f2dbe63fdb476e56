#include "ret3d/core/transform.h"

#include <cmath>

#include "ret3d/core/geometry.h"

namespace ret3d {

double yawOf(const Eigen::Isometry3d& T) {
  const Eigen::Matrix3d R = T.linear();
  return std::atan2(R(1, 0), R(0, 0));
}

Eigen::Isometry3d makeTransform(double x, double y, double z, double yaw) {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  T.translation() = Eigen::Vector3d(x, y, z);
  return T;
}

Box transformBox(const Box& b, const Eigen::Isometry3d& T) {
  Box out = b;
  const Eigen::Vector3d c = T * b.center();
  out.x = c.x();
  out.y = c.y();
  out.z = c.z();
  // Heading: transform the heading direction and take its angle in the new xy plane (exact for any rotation
  // whose z axis stays near vertical).
  const Eigen::Vector3d dir = T.linear() * Eigen::Vector3d(std::cos(b.yaw), std::sin(b.yaw), 0.0);
  out.yaw = wrapAngle(std::atan2(dir.y(), dir.x()));
  const Eigen::Vector3d v = T.linear() * Eigen::Vector3d(b.vx, b.vy, 0.0);
  out.vx = v.x();
  out.vy = v.y();
  return out;
}

PointCloud transformCloud(const PointCloud& cloud, const Eigen::Isometry3d& T) {
  PointCloud out = cloud;
  const Eigen::Matrix3f R = T.linear().cast<float>();
  const Eigen::Vector3f t = T.translation().cast<float>();
  for (Point& p : out.points) {
    const Eigen::Vector3f q = R * Eigen::Vector3f(p.x, p.y, p.z) + t;
    p.x = q.x();
    p.y = q.y();
    p.z = q.z();
  }
  return out;
}

}  // namespace ret3d
