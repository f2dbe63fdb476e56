// Writes one simulated sequence in the KITTI tracking layout:
//   training/velodyne/SSSS/FFFFFF.bin   x y z intensity (float32)
//   training/label_02/SSSS.txt          every labelled object, all around the vehicle (see ground_truth.h)
//   training/calib/SSSS.txt             the KITTI-like calibration
//   training/pose/SSSS.txt              camera poses T_cam0_cam_t = Tr * T_velo0_velo_t * Tr^-1, Tr the rigid part of
//                                       R0_rect * Tr_velo_to_cam, so TrackingDataset::lidarPoses reads back the LiDAR poses
//   training/sim_info/SSSS.txt          what KITTI labels cannot carry (docs/SIMULATOR.md): LiDAR-frame box, velocity,
//                                       points, rays, visible fraction, camera truncation and visibility
#pragma once

#include <string>
#include <vector>

#include "ret3d/io/kitti.h"
#include "ret3d/sim/ground_truth.h"

namespace ret3d {
namespace sim {

class SequenceWriter {
 public:
  SequenceWriter(const std::string& root, const std::string& sequence, const kitti::Calibration& calib);
  void writeFrame(int frame, const PointCloud& cloud, const std::vector<ObjectTruth>& truth,
                  const Eigen::Isometry3d& T_velo0_velo);
  // Replay: write these camera poses verbatim instead of converting the LiDAR poses.
  void setCameraPoses(std::vector<Eigen::Isometry3d> poses) { camera_poses_ = std::move(poses); }
  void finish();
  const std::string& trainingDir() const { return dir_; }

 private:
  std::string dir_, seq_;
  kitti::Calibration calib_;
  std::vector<kitti::Label> labels_;
  std::vector<Eigen::Isometry3d> lidar_poses_, camera_poses_;
  std::string info_;
};

// The rigid transform LiDAR -> rectified camera (R0_rect * Tr_velo_to_cam with its rotation orthonormalised).
Eigen::Isometry3d lidarToCamera(const kitti::Calibration& calib);

}  // namespace sim
}  // namespace ret3d
