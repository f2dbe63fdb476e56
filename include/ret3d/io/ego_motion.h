// Ego poses of a KITTI tracking sequence for the commands that run the tracker: from pose/ or oxts/, from a pose file
// given on the command line, or estimated from the scans themselves (core/scan_matching.h) when there are none.
#pragma once

#include <string>
#include <vector>

#include <Eigen/Geometry>

#include "ret3d/io/kitti.h"

namespace ret3d {
namespace io {

// LiDAR poses T_velo0_velo_t (one per frame index up to the last scan) from scan matching of consecutive scans, each
// match started from the previous motion (constant velocity). A failed match keeps the previous motion (a warning);
// frames missing between scans keep the pose of the scan before. Logs the distance and turn it found.
std::vector<Eigen::Isometry3d> estimateLidarPoses(const kitti::TrackingDataset& ds, const std::string& seq);

// Where a sequence's ego poses come from.
struct EgoPoseSource {
  std::string poses_file;     // non-empty: this file (pose/SSSS.txt's format: camera poses, KITTI odometry convention)
  bool scan_matching = true;  // without pose/, oxts/ or a file: estimate the motion from the scans
};

// The LiDAR poses of `seq`: the file, else pose/ or oxts/, else (with scan_matching and scans) estimated from the
// scans, saying so in the log; empty when none of these applies.
std::vector<Eigen::Isometry3d> sequenceLidarPoses(const kitti::TrackingDataset& ds, const std::string& seq,
                                                  const EgoPoseSource& source = {});

}  // namespace io
}  // namespace ret3d
