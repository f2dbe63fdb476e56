// Private to src/core: what the two registrations of scan_matching.h share (the points they match, the ground-plane
// projection) and the registrations themselves (scan_matching.cpp: ICP; scan_matching_gicp.cpp: PCL's GICP).
#pragma once

#include <vector>

#include <Eigen/Geometry>

#include "ret3d/core/scan_matching.h"

namespace ret3d {
namespace scan_matching {

using Points = std::vector<Eigen::Vector3d>;

// One centroid per voxel (options.voxel_size) of the points above options.ground_height within options.max_range.
Points downsample(const PointCloud& cloud, const ScanMatchingOptions& options);
// The rigid motion (x, y, 0) with a rotation by yaw about z.
Eigen::Isometry3d planar(double x, double y, double yaw);
// T projected on the ground plane: its x, y and the yaw of its rotation.
Eigen::Isometry3d planarPart(const Eigen::Isometry3d& T);

ScanMatch matchIcp(const PointCloud& source, const PointCloud& target, const Eigen::Isometry3d& initial,
                   const ScanMatchingOptions& options);
ScanMatch matchGicp(const PointCloud& source, const PointCloud& target, const Eigen::Isometry3d& initial,
                    const ScanMatchingOptions& options);

}  // namespace scan_matching
}  // namespace ret3d
