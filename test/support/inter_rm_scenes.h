// Synthetic tracked sequences for the InterRM tests: objects moving at constant velocity, observed with noisy boxes;
// the target is the true current box, so the history carries information the current box alone does not.
#pragma once

#include <cmath>
#include <random>
#include <vector>

#include "ret3d/core/geometry.h"
#include "ret3d/relation/inter_rm_learner.h"

namespace ret3d {
namespace test {

inline relation::InterRMSample makeInterSample(std::mt19937_64& rng, int length) {
  std::uniform_real_distribution<double> u(0.0, 1.0);
  std::normal_distribution<double> noise(0.0, 1.0);
  const int cls = static_cast<int>(u(rng) * 3);
  const ObjectClass label = kDetectedClasses[static_cast<std::size_t>(cls)];
  const double l = cls == 0 ? 3.9 : (cls == 1 ? 0.8 : 1.8), w = cls == 0 ? 1.6 : 0.6, h = cls == 0 ? 1.5 : 1.7;
  const double speed = (cls == 0 ? 12.0 : 3.0) * u(rng), heading = (u(rng) * 2 - 1) * M_PI;
  const double x0 = 5 + 40 * u(rng), y0 = (u(rng) * 2 - 1) * 20;
  relation::InterRMSample s;
  for (int k = 0; k < length; ++k) {
    const double dt = -0.1 * k;
    Box truth;
    truth.x = x0 + speed * std::cos(heading) * dt;
    truth.y = y0 + speed * std::sin(heading) * dt;
    truth.z = -0.8;
    truth.length = l, truth.width = w, truth.height = h;
    truth.yaw = heading;
    truth.label = label;
    Box obs = truth;
    obs.x += 0.3 * noise(rng), obs.y += 0.3 * noise(rng), obs.z += 0.1 * noise(rng);
    obs.length *= std::exp(0.08 * noise(rng)), obs.width *= std::exp(0.08 * noise(rng));
    obs.yaw = wrapAngle(obs.yaw + 0.08 * noise(rng));
    obs.score = static_cast<float>(0.5 + 0.5 * u(rng));
    obs.track_id = 7;
    if (k == 0) s.target = truth;
    s.sequence.boxes.push_back(obs);
    s.sequence.dt.push_back(dt);
  }
  return s;
}

inline std::vector<relation::InterRMSample> makeInterSamples(std::size_t n, std::uint64_t seed, int max_len = 20) {
  std::mt19937_64 rng(seed);
  std::uniform_int_distribution<int> len(1, max_len);
  std::vector<relation::InterRMSample> out;
  for (std::size_t i = 0; i < n; ++i) out.push_back(makeInterSample(rng, len(rng)));
  return out;
}

}  // namespace test
}  // namespace ret3d
