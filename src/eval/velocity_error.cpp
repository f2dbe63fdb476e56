#include "ret3d/eval/velocity_error.h"

#include <algorithm>
#include <cmath>
#include <numeric>

#include "ret3d/core/stats.h"

namespace ret3d {
namespace eval {

std::map<ObjectClass, VelocityErrorStats> velocityErrors(const std::vector<VelocityFrame>& frames, double moving_speed,
                                                         double match_distance) {
  std::map<ObjectClass, std::vector<double>> moving, still;
  std::map<ObjectClass, VelocityErrorStats> out;
  for (const VelocityFrame& f : frames) {
    std::vector<std::size_t> order(f.pred.size());
    std::iota(order.begin(), order.end(), 0);
    std::sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) { return f.pred[a].score > f.pred[b].score; });
    std::vector<bool> used(f.pred.size(), false);
    for (std::size_t g = 0; g < f.gt.size(); ++g) {
      if (g >= f.gt_valid.size() || !f.gt_valid[g]) continue;
      const Box& gt = f.gt[g];
      const double speed = std::hypot(gt.vx, gt.vy);
      if (speed > moving_speed) ++out[gt.label].moving_gt;
      for (const std::size_t p : order) {
        const Box& d = f.pred[p];
        if (used[p] || d.label != gt.label || std::hypot(d.x - gt.x, d.y - gt.y) > match_distance) continue;
        used[p] = true;
        const double err = std::hypot(d.vx - gt.vx, d.vy - gt.vy);
        (speed > moving_speed ? moving : still)[gt.label].push_back(err);
        break;
      }
    }
  }
  for (const auto& [c, v] : moving) {
    VelocityErrorStats& s = out[c];
    s.moving_matched = v.size();
    s.moving_median = percentile(v, 50);
    s.moving_p90 = percentile(v, 90);
  }
  for (const auto& [c, v] : still) {
    VelocityErrorStats& s = out[c];
    s.static_matched = v.size();
    s.static_median = percentile(v, 50);
  }
  return out;
}

}  // namespace eval
}  // namespace ret3d
