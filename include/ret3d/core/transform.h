// Rigid transforms (Eigen::Isometry3d) applied to boxes and clouds.
#pragma once

#include <Eigen/Geometry>

#include "ret3d/core/types.h"

namespace ret3d {

// Yaw (rotation about z) of a rotation, assuming the rotation is mostly about z (as ego motion is).
double yawOf(const Eigen::Isometry3d& T);
// A transform from x, y, z, yaw.
Eigen::Isometry3d makeTransform(double x, double y, double z, double yaw);

// The box expressed in the target frame: centre transformed, yaw increased by the transform's yaw (wrapped),
// velocity rotated. Size, score, label, ids unchanged.
Box transformBox(const Box& b, const Eigen::Isometry3d& T);
// Every point transformed; intensity, time and ring kept.
PointCloud transformCloud(const PointCloud& cloud, const Eigen::Isometry3d& T);

}  // namespace ret3d
