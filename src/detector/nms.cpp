#include "ret3d/detector/nms.h"

#include <algorithm>
#include <cmath>
#include <numeric>

#include "ret3d/core/geometry.h"

namespace ret3d {

std::vector<std::size_t> rotatedNms(const std::vector<Box>& boxes, double iou_threshold, bool per_class,
                                    std::size_t max_keep) {
  std::vector<std::size_t> order(boxes.size());
  std::iota(order.begin(), order.end(), 0);
  std::stable_sort(order.begin(), order.end(),
                   [&](std::size_t a, std::size_t b) { return boxes[a].score > boxes[b].score; });
  std::vector<std::size_t> keep;
  for (std::size_t i : order) {
    const Box& b = boxes[i];
    const double rb = 0.5 * std::hypot(b.length, b.width);
    bool suppressed = false;
    for (std::size_t j : keep) {
      const Box& k = boxes[j];
      if (per_class && k.label != b.label) continue;
      // Circumscribed circles apart: no overlap, skip the exact polygon clipping.
      const double rk = 0.5 * std::hypot(k.length, k.width);
      if (std::hypot(b.x - k.x, b.y - k.y) >= rb + rk) continue;
      if (bevIoU(b, k) > iou_threshold) {
        suppressed = true;
        break;
      }
    }
    if (!suppressed) {
      keep.push_back(i);
      if (max_keep && keep.size() >= max_keep) break;
    }
  }
  return keep;
}

std::vector<Box> voteBoxes(const std::vector<Box>& boxes, const std::vector<std::size_t>& keep, double iou_threshold) {
  std::vector<Box> out;
  out.reserve(keep.size());
  for (std::size_t i : keep) {
    const Box& k = boxes[i];
    const double rk = 0.5 * std::hypot(k.length, k.width);
    double sw = 0, x = 0, y = 0, z = 0, l = 0, w = 0, h = 0, dyaw = 0, vx = 0, vy = 0;
    for (const Box& b : boxes) {
      if (b.label != k.label) continue;
      if (std::hypot(b.x - k.x, b.y - k.y) >= rk + 0.5 * std::hypot(b.length, b.width)) continue;
      if (&b != &k && bevIoU(b, k) < iou_threshold) continue;
      const double s = b.score;
      sw += s;
      x += s * b.x, y += s * b.y, z += s * b.z;
      l += s * std::log(b.length), w += s * std::log(b.width), h += s * std::log(b.height);
      // The difference modulo pi, in [-pi/2, pi/2).
      dyaw += s * (wrapAngle(2 * (b.yaw - k.yaw)) / 2);
      vx += s * b.vx, vy += s * b.vy;
    }
    Box v = k;
    if (sw > 0) {
      v.x = x / sw, v.y = y / sw, v.z = z / sw;
      v.length = std::exp(l / sw), v.width = std::exp(w / sw), v.height = std::exp(h / sw);
      v.yaw = wrapAngle(k.yaw + dyaw / sw);
      v.vx = vx / sw, v.vy = vy / sw;
    }
    out.push_back(v);
  }
  return out;
}

}  // namespace ret3d
