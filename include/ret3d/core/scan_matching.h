// Ego motion between two consecutive LiDAR scans without poses, from voxel-downsampled non-ground points, in the
// ground plane (x, y, yaw): the ground is left out (it constrains only z, roll and pitch), and road vehicles move in
// that plane. Two registrations (ScanMatcher): a small point-to-plane ICP written here, with a voxel hash for the
// nearest neighbours, and PCL's generalized ICP on the same points. Used for
// scan folders that come without poses (io/ego_motion.h: `ret3d autolabel`, `ret3d detect`); `ret3d egomotion` measures
// both (docs/RESULTS.md, "Ego motion from the scans").
#pragma once

#include <Eigen/Geometry>

#include <string>

#include "ret3d/core/types.h"

namespace ret3d {

enum class ScanMatcher {
  Icp,   // point-to-plane ICP in (x, y, yaw), coarse to fine (the stages below)
  Gicp,  // PCL's pcl::GeneralizedIterativeClosestPoint (plane-to-plane), 6 DoF, projected on the ground plane
};

struct ScanMatchingOptions {
  ScanMatcher matcher = ScanMatcher::Icp;
  double voxel_size = 0.4;      // m: both scans are reduced to one centroid per voxel
  double ground_height = -1.3;  // m in the sensor frame: points below are ground (KITTI's sensor is 1.73 m up)
  double max_range = 50.0;      // m (BEV): farther points are sparse and noisy
  // Correspondence distance (m) of the coarse-to-fine stages; each stage iterates up to `iterations` times.
  double first_distance = 2.0, last_distance = 0.5;
  int stages = 3, iterations = 15;
  int min_correspondences = 50;  // fewer: the match failed
  // Gicp: correspondence distance (m) and iterations; converged as PCL says, with min_correspondences source points
  // within last_distance of the target after the match.
  double gicp_distance = 1.0;
  int gicp_iterations = 50;
};

struct ScanMatch {
  Eigen::Isometry3d source_to_target = Eigen::Isometry3d::Identity();
  bool converged = false;        // enough correspondences in the last stage
  int correspondences = 0;       // in the last iteration
  double rmse = 0;               // m, of those correspondences
};

// The rigid motion T with target ~ T * source (both in their own sensor frames), started from `initial` (e.g. the
// previous frame's motion). For consecutive scans t-1 (target) and t (source), T is frame t's pose in frame t-1.
ScanMatch matchScans(const PointCloud& source, const PointCloud& target,
                     const Eigen::Isometry3d& initial = Eigen::Isometry3d::Identity(),
                     const ScanMatchingOptions& options = {});

// "icp" / "gicp" <-> ScanMatcher; parseScanMatcher throws std::invalid_argument naming the accepted values.
ScanMatcher parseScanMatcher(const std::string& name);
const char* scanMatcherName(ScanMatcher matcher);

}  // namespace ret3d
