// Synthetic frames for the IntraRM tests: ground-truth objects in plausible places, and "detections" that are those
// objects with noise plus some false positives, as a base detector would give.
#pragma once

#include <random>
#include <vector>

#include "ret3d/relation/intra_rm_learner.h"

namespace ret3d {
namespace relation {
namespace test {

inline Box randomObject(std::mt19937& rng, double extent = 40.0) {
  std::uniform_real_distribution<double> u(-1, 1);
  Box b;
  const int c = static_cast<int>(rng() % 3);
  b.label = kDetectedClasses[static_cast<std::size_t>(c)];
  const double l[3] = {3.9, 0.8, 1.8}, w[3] = {1.6, 0.6, 0.6}, h[3] = {1.5, 1.7, 1.7};
  b.length = l[c] * (1 + 0.1 * u(rng));
  b.width = w[c] * (1 + 0.1 * u(rng));
  b.height = h[c] * (1 + 0.1 * u(rng));
  b.x = extent * (0.5 + 0.5 * u(rng));
  b.y = 0.6 * extent * u(rng);
  b.z = -1.0 + 0.5 * b.height + 0.2 * u(rng);
  b.yaw = M_PI * u(rng);
  b.score = 0.9f;
  return b;
}

// Detections of a frame with `objects` ground-truth objects; features (random, correlated with the error) when
// feature_dim > 0.
inline IntraRMFrame randomFrame(std::mt19937& rng, int objects, std::size_t feature_dim = 0,
                                const IntraRMTrainConfig& config = {}) {
  std::normal_distribution<double> noise(0, 1);
  FrameGroundTruth gt;
  IntraRMFrame f;
  for (int i = 0; i < objects; ++i) {
    const Box g = randomObject(rng);
    gt.boxes.push_back(g);
    Box d = g;
    // A systematic offset (the base detector places boxes 0.3 m short along x) plus noise: learnable.
    d.x -= 0.3 + 0.1 * noise(rng);
    d.y += 0.1 * noise(rng);
    d.yaw += 0.05 * noise(rng);
    d.score = static_cast<float>(0.5 + 0.1 * noise(rng));
    f.detections.boxes.push_back(d);
  }
  for (int i = 0; i < objects / 3 + 1; ++i) {  // false positives
    Box d = randomObject(rng);
    d.score = static_cast<float>(0.3 + 0.1 * noise(rng));
    f.detections.boxes.push_back(d);
  }
  f.detections.feature_dim = feature_dim;
  for (std::size_t i = 0; i < f.detections.size() * feature_dim; ++i)
    f.detections.features.push_back(static_cast<float>(noise(rng)));
  f.targets = assignIntraRMTargets(f.detections.boxes, gt, config);
  return f;
}

}  // namespace test
}  // namespace relation
}  // namespace ret3d
