#include "ret3d/io/track_velocity.h"

#include <unordered_map>

namespace ret3d {

std::vector<std::vector<bool>> setTrackVelocities(std::vector<std::vector<Box>>* frames,
                                                  const std::vector<Eigen::Isometry3d>& poses, double frame_period) {
  const int n = static_cast<int>(frames->size());
  auto motion = [&](int from, int to) -> Eigen::Isometry3d {  // T_to_from
    if (from < 0 || to < 0 || from >= static_cast<int>(poses.size()) || to >= static_cast<int>(poses.size()))
      return Eigen::Isometry3d::Identity();
    return poses[static_cast<std::size_t>(to)].inverse() * poses[static_cast<std::size_t>(from)];
  };
  // Centres by track id per frame, read before any velocity is written.
  std::vector<std::unordered_map<int, Eigen::Vector3d>> centres(frames->size());
  for (int f = 0; f < n; ++f)
    for (const Box& b : (*frames)[static_cast<std::size_t>(f)])
      if (b.track_id != 0) centres[static_cast<std::size_t>(f)][b.track_id] = b.center();
  std::vector<std::vector<bool>> valid(frames->size());
  for (int f = 0; f < n; ++f) {
    auto& boxes = (*frames)[static_cast<std::size_t>(f)];
    valid[static_cast<std::size_t>(f)].assign(boxes.size(), false);
    for (std::size_t k = 0; k < boxes.size(); ++k) {
      Box& b = boxes[k];
      b.vx = b.vy = 0;
      if (b.track_id == 0) continue;
      for (const int other : {f - 1, f + 1}) {
        if (other < 0 || other >= n) continue;
        const auto it = centres[static_cast<std::size_t>(other)].find(b.track_id);
        if (it == centres[static_cast<std::size_t>(other)].end()) continue;
        const Eigen::Vector3d c = motion(other, f) * it->second;
        const double sign = other < f ? 1.0 : -1.0;
        b.vx = sign * (b.x - c.x()) / frame_period;
        b.vy = sign * (b.y - c.y()) / frame_period;
        valid[static_cast<std::size_t>(f)][k] = true;
        break;
      }
    }
  }
  return valid;
}

}  // namespace ret3d
