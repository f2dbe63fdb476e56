// Ground truth of one simulated frame: for every labelled actor within the label range with enough returns, its
// LiDAR-frame box (with num_points: its own returns inside the box), the rays that reached it and the rays that would
// have reached it with nothing in the way (so the visible fraction), and the camera label KITTI evaluation needs:
// 2D box, truncation and occlusion level from casting rays through the KITTI-like front camera. Objects all around
// the vehicle are labelled (Waymo-style evaluation is 360 degrees); those outside the camera's view get truncation 2
// (fully truncated), occlusion 3 (unknown) and an empty 2D box, so KITTI-style evaluation drops them.
#pragma once

#include <vector>

#include "ret3d/core/types.h"
#include "ret3d/io/kitti.h"
#include "ret3d/sim/actors.h"
#include "ret3d/sim/ray_caster.h"

namespace ret3d {
namespace sim {

struct ObjectTruth {
  std::size_t actor = 0;        // index into Traffic::actors
  Box box;                      // LiDAR frame; num_points = the object's own returns inside the box
  std::uint32_t hits = 0;       // rays whose first hit is the object (before drop-out)
  std::uint32_t unoccluded = 0; // rays that hit the object when nothing else is there
  double visible_fraction = 0;  // hits / unoccluded, in [0, 1]
  double camera_truncation = 1; // fraction of the object's mesh outside image 2 (1 = not in view)
  double camera_visible = 0;    // fraction of the object's image rays not blocked by something else
  kitti::Label label;           // tracking label (frame, track id = Box::track_id - 1, type, camera fields)
};

struct TruthOptions {
  double label_range = 80;
  int min_points = 1;
  int camera_samples = 10;      // rays per side of the 2D box grid for the camera occlusion estimate
  Eigen::Vector2d image_size{1242, 375};
  int threads = 2;
};

// Labels one frame. `T_world_lidar` is the sensor pose the sweep was cast from; `ego_velocity`/`yaw_rate` as given
// to RayCaster::cast (only used with motion distortion).
std::vector<ObjectTruth> labelFrame(const std::vector<Actor>& actors, const RayCaster& caster, const Sweep& sweep,
                                    const Eigen::Isometry3d& T_world_lidar, const kitti::Calibration& calib,
                                    const TruthOptions& options, int frame,
                                    const Eigen::Vector3d& ego_velocity = Eigen::Vector3d::Zero(),
                                    double yaw_rate = 0);

// The KITTI occlusion level for a visible fraction: 0 (>= 0.8), 1 (>= 0.4), 2 (less).
int occlusionLevel(double visible);

}  // namespace sim
}  // namespace ret3d
