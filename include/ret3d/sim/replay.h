// Real traffic replay: the actors (class, size, trajectory) and the ego path of a KITTI tracking sequence
// (label_02 + pose + calib), as simulator actors with a world box per frame. The world frame is the first LiDAR
// frame. Car, Pedestrian and Cyclist tracks become labelled actors (meshes fitted to their boxes); Van and Truck
// tracks are drawn as vans but not labelled (KITTI keeps them apart from Car); other types are skipped.
#pragma once

#include <string>
#include <vector>

#include "ret3d/io/kitti.h"
#include "ret3d/sim/actors.h"

namespace ret3d {
namespace sim {

struct ReplayData {
  std::vector<Actor> actors;
  std::vector<Eigen::Isometry3d> lidar_poses;   // T_velo0_velo_t per frame
  std::vector<Eigen::Isometry3d> camera_poses;  // the pose file's lines, verbatim
  kitti::Calibration calib;
  int frames = 0;
};

// Reads sequence `sequence` of the tracking dataset at `root`; at most `max_frames` frames (<= 0: all).
// Throws std::runtime_error when labels, poses or calibration are missing.
ReplayData loadReplay(const std::string& root, const std::string& sequence, const SimConfig& config, Rng& rng,
                      int max_frames);

}  // namespace sim
}  // namespace ret3d
