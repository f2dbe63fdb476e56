#include "ret3d/relation/intra_rm_targets.h"

#include <cmath>
#include <utility>

#include "ret3d/core/geometry.h"

namespace ret3d {
namespace relation {

int classIndex(ObjectClass c) {
  switch (c) {
    case ObjectClass::Car: return 0;
    case ObjectClass::Pedestrian: return 1;
    case ObjectClass::Cyclist: return 2;
    default: return -1;
  }
}

namespace {

// Heading residual modulo pi, in [-pi/2, pi/2): the KITTI 3D/BEV IoU of a box is the same when it faces backwards,
// so only the axis is corrected; flipping a heading is left to the tracker's motion.
float headingResidual(double from, double to) {
  double d = std::fmod(to - from + M_PI / 2, M_PI);
  if (d < 0) d += M_PI;
  return static_cast<float>(d - M_PI / 2);
}

// Cheap rejection before the exact rotated IoU: BEV circumscribed circles must intersect.
bool mayOverlap(const Box& a, const Box& b) {
  const double ra = 0.5 * std::hypot(a.length, a.width), rb = 0.5 * std::hypot(b.length, b.width);
  return std::hypot(a.x - b.x, a.y - b.y) < ra + rb;
}

}  // namespace

std::vector<IntraRMTarget> assignIntraRMTargets(const std::vector<Box>& detections, const FrameGroundTruth& gt,
                                                const IntraRMTrainConfig& config,
                                                const std::vector<bool>& dont_care) {
  std::vector<IntraRMTarget> out(detections.size());
  for (std::size_t i = 0; i < detections.size(); ++i) {
    const Box& d = detections[i];
    IntraRMTarget& t = out[i];
    const int ci = classIndex(d.label);
    // Best BEV IoU per class channel (class-aware: a channel only looks at ground truth of its class).
    std::array<double, 3> best_iou{{0, 0, 0}};
    int best_own = -1;
    for (std::size_t g = 0; g < gt.boxes.size(); ++g) {
      const int cg = classIndex(gt.boxes[g].label);
      if (cg < 0 || !mayOverlap(d, gt.boxes[g])) continue;
      const double iou = bevIoU(d, gt.boxes[g]);
      if (iou > best_iou[cg]) {
        best_iou[cg] = iou;
        if (cg == ci) best_own = static_cast<int>(g);
      }
    }
    bool positive = false;
    for (int k = 0; k < 3; ++k) {
      if (best_iou[k] >= config.cls_pos_iou[k]) {
        t.cls[k] = 1.0f;
        if (k == ci) positive = true;
      }
    }
    if (ci >= 0) t.iou = static_cast<float>(best_iou[ci]);
    if (!positive) {
      bool ignore = i < dont_care.size() && dont_care[i];
      for (const Box& s : gt.similar) {
        if (ignore) break;
        if (s.label == d.label && mayOverlap(d, s) && bevIoU(d, s) >= 0.5) ignore = true;
      }
      if (ignore) t.cls_weight = 0;
    }
    if (ci >= 0 && best_own >= 0 && best_iou[ci] >= config.reg_min_iou[ci]) {
      const Box& g = gt.boxes[static_cast<std::size_t>(best_own)];
      t.regress = true;
      t.dx = static_cast<float>(g.x - d.x);
      t.dy = static_cast<float>(g.y - d.y);
      t.dz = static_cast<float>(g.z - d.z);
      // A rectangle turned by 90 degrees with length and width swapped is the same rectangle: take the description
      // of the ground truth closest to the detection's heading, so a near-square box (a pedestrian) whose heading
      // is a quarter turn off gets consistent size targets instead of swapped ones.
      double dyaw = headingResidual(d.yaw, g.yaw), gl = g.length, gw = g.width;
      if (std::abs(dyaw) > M_PI / 4) {
        std::swap(gl, gw);
        dyaw -= std::copysign(M_PI / 2, dyaw);
      }
      t.dl = static_cast<float>(std::log(std::max(gl, 1e-3) / std::max(d.length, 1e-3)));
      t.dw = static_cast<float>(std::log(std::max(gw, 1e-3) / std::max(d.width, 1e-3)));
      t.dh = static_cast<float>(std::log(std::max(g.height, 1e-3) / std::max(d.height, 1e-3)));
      t.dyaw = static_cast<float>(dyaw);
    }
  }
  return out;
}

}  // namespace relation
}  // namespace ret3d
