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

}  // namespace ret3d
