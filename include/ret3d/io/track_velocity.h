// Ground-truth velocities of labelled boxes from their track ids: the displacement of the same track between
// consecutive frames, both in the current sensor frame (the ego motion from the poses removed), over the frame period.
// Used by detector training (velocity targets) and by the velocity-error report of `ret3d detect`.
#pragma once

#include <vector>

#include <Eigen/Geometry>

#include "ret3d/core/types.h"

namespace ret3d {

// frames[f]: the boxes of frame f (LiDAR frame f, track_id > 0 for tracked ones); poses[f]: T_world_lidar(f), may
// be empty (no ego motion). Sets vx, vy of every box from the same track in frame f-1, else in frame f+1; returns,
// per frame and box, whether a velocity was found (boxes without a neighbour get vx = vy = 0).
std::vector<std::vector<bool>> setTrackVelocities(std::vector<std::vector<Box>>* frames,
                                                  const std::vector<Eigen::Isometry3d>& poses, double frame_period);

}  // namespace ret3d
