#include "ret3d/io/sweeps.h"

namespace ret3d {
namespace io {

bool forEachSweep(const kitti::TrackingDataset& ds, const std::string& seq, const std::function<void(const Sweep&)>& visit) {
  const auto poses = ds.lidarPoses(seq);
  forEachSweep(ds, seq, poses, visit);
  return !poses.empty();
}

void forEachSweep(const kitti::TrackingDataset& ds, const std::string& seq, const std::vector<Eigen::Isometry3d>& poses,
                  const std::function<void(const Sweep&)>& visit) {
  auto pose = [&](int f) {
    return f >= 0 && f < static_cast<int>(poses.size()) ? poses[static_cast<std::size_t>(f)]
                                                        : Eigen::Isometry3d::Identity();
  };
  PointCloud previous;
  int previous_frame = -2;
  for (const int frame : ds.frames(seq)) {
    const PointCloud cloud = kitti::readVelodyne(ds.velodynePath(seq, frame));
    Sweep s;
    s.frame = frame;
    s.cloud = &cloud;
    s.previous = previous_frame == frame - 1 ? &previous : nullptr;
    s.pose = pose(frame);
    s.prev_to_current = s.pose.inverse() * pose(frame - 1);
    visit(s);
    previous = cloud;
    previous_frame = frame;
  }
}

}  // namespace io
}  // namespace ret3d
