// The scans of one KITTI tracking sequence in order, each with the previous sweep and the ego motion between them
// (from pose/ or oxts/; identity when absent), as a detector consumes them online.
#pragma once

#include <functional>
#include <string>
#include <vector>

#include <Eigen/Geometry>

#include "ret3d/core/types.h"
#include "ret3d/io/kitti.h"

namespace ret3d {
namespace io {

struct Sweep {
  int frame = 0;
  const PointCloud* cloud = nullptr;
  const PointCloud* previous = nullptr;  // null for the first scan and after a gap in the frame numbers
  Eigen::Isometry3d prev_to_current = Eigen::Isometry3d::Identity();  // previous-sweep point -> current frame
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();             // sensor -> first frame of the sequence
};

// Calls `visit` for every scan of `seq`; returns false when the sequence has no poses (motion taken as zero).
bool forEachSweep(const kitti::TrackingDataset& ds, const std::string& seq, const std::function<void(const Sweep&)>& visit);
// The same with the ego poses given (e.g. estimated from the scans): poses[frame], identity beyond them.
void forEachSweep(const kitti::TrackingDataset& ds, const std::string& seq, const std::vector<Eigen::Isometry3d>& poses,
                  const std::function<void(const Sweep&)>& visit);

}  // namespace io
}  // namespace ret3d
