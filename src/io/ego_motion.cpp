#include "ret3d/io/ego_motion.h"

#include <cmath>
#include <filesystem>
#include <iomanip>
#include <sstream>
#include <stdexcept>

#include "ret3d/core/log.h"
#include "ret3d/core/progress.h"
#include "ret3d/core/scan_matching.h"
#include "ret3d/core/transform.h"

namespace ret3d {
namespace io {

std::vector<Eigen::Isometry3d> estimateLidarPoses(const kitti::TrackingDataset& ds, const std::string& seq) {
  const std::vector<int> frames = ds.frames(seq);
  std::vector<Eigen::Isometry3d> poses(frames.empty() ? 0 : static_cast<std::size_t>(frames.back()) + 1,
                                       Eigen::Isometry3d::Identity());
  PointCloud previous;
  int previous_frame = -1;
  Eigen::Isometry3d motion = Eigen::Isometry3d::Identity();
  std::size_t failed = 0;
  ProgressBar bar("ego motion " + seq, frames.size());
  for (const int f : frames) {
    PointCloud cloud = kitti::readVelodyne(ds.velodynePath(seq, f));
    if (previous_frame >= 0) {
      const ScanMatch m = matchScans(cloud, previous, motion);
      if (m.converged) {
        motion = m.source_to_target;
      } else {
        ++failed;
        RET3D_WARN("sequence " << seq << ": scan matching of frame " << f << " to " << previous_frame << " failed ("
                               << m.correspondences << " correspondences); the previous motion is kept");
      }
      poses[static_cast<std::size_t>(f)] = poses[static_cast<std::size_t>(previous_frame)] * motion;
    }
    // Frames missing before the next scan keep this pose.
    for (int g = f + 1; g < static_cast<int>(poses.size()); ++g) poses[static_cast<std::size_t>(g)] = poses[f];
    previous = std::move(cloud);
    previous_frame = f;
    bar.tick();
  }
  if (poses.size() > 1) {
    const Eigen::Isometry3d& last = poses.back();
    std::ostringstream s;
    s << std::fixed << std::setprecision(1) << last.translation().head<2>().norm() << " m, "
      << yawOf(last) * 180.0 / M_PI << " deg over " << poses.size() << " frames";
    RET3D_INFO("sequence " << seq << ": ego motion estimated from the scans (" << failed
                           << " failed matches): " << s.str());
  }
  return poses;
}

std::vector<Eigen::Isometry3d> sequenceLidarPoses(const kitti::TrackingDataset& ds, const std::string& seq,
                                                  const EgoPoseSource& source) {
  if (!source.poses_file.empty()) {
    if (!std::filesystem::is_regular_file(source.poses_file))
      throw std::runtime_error("--poses " + source.poses_file + ": no such file");
    return kitti::cameraPosesToLidar(kitti::readPoses(source.poses_file), ds.calibration(seq));
  }
  std::vector<Eigen::Isometry3d> poses = ds.lidarPoses(seq);
  if (!poses.empty() || !source.scan_matching || ds.frames(seq).empty()) return poses;
  RET3D_INFO("sequence " << seq << ": no ego poses (pose/ or oxts/); estimating the ego motion from the scans "
                         "(scan matching)");
  return estimateLidarPoses(ds, seq);
}

}  // namespace io
}  // namespace ret3d
