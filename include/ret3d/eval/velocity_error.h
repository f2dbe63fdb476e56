// Velocity error of detections against ground truth (CenterPoint's velocity, LWD-3D + Ret3D §3.1): each ground-truth
// object with a known velocity is matched to the highest-scoring unmatched detection of its class whose centre lies
// within `match_distance` in BEV; the error is the norm of the BEV velocity difference (m/s). Reported for moving
// objects (ground-truth speed above `moving_speed`) and for all, per class.
#pragma once

#include <map>
#include <vector>

#include "ret3d/core/types.h"

namespace ret3d {
namespace eval {

struct VelocityErrorStats {
  std::size_t moving_gt = 0;      // ground-truth objects with a known velocity above moving_speed
  std::size_t moving_matched = 0;
  double moving_median = 0, moving_p90 = 0;  // m/s over the matched moving objects
  std::size_t static_matched = 0;
  double static_median = 0;                  // m/s over matched objects below moving_speed
};

struct VelocityFrame {
  std::vector<Box> gt;             // velocity set where gt_valid is true
  std::vector<bool> gt_valid;
  std::vector<Box> pred;           // with predicted velocity and score
};

std::map<ObjectClass, VelocityErrorStats> velocityErrors(const std::vector<VelocityFrame>& frames,
                                                         double moving_speed = 0.5, double match_distance = 2.0);

}  // namespace eval
}  // namespace ret3d
