// A street-like scene for the tests of scan matching and ego-motion estimation.
#pragma once

#include <random>

#include "ret3d/core/types.h"

namespace ret3d {
namespace test {

// A street-like scene in the sensor frame: a ground plane, two building walls at an angle, car-sized blocks and
// poles, sampled at random.
inline PointCloud streetScene(std::mt19937* rng) {
  std::uniform_real_distribution<double> u(0, 1);
  PointCloud c;
  auto add = [&](double x, double y, double z) {
    c.points.push_back({static_cast<float>(x), static_cast<float>(y), static_cast<float>(z), 0.5f});
  };
  for (int i = 0; i < 20000; ++i) add(-40 + 80 * u(*rng), -20 + 40 * u(*rng), -1.73);  // ground
  for (int i = 0; i < 15000; ++i) add(-40 + 80 * u(*rng), 12 + 0.1 * u(*rng), -1.7 + 8 * u(*rng));  // left wall
  for (int i = 0; i < 15000; ++i) {  // right wall, slanted
    const double s = -40 + 80 * u(*rng);
    add(s, -10 - 0.15 * s, -1.7 + 6 * u(*rng));
  }
  for (int k = 0; k < 8; ++k) {  // blocks
    const double cx = -30 + 8 * k, cy = (k % 2 ? 6 : -5);
    for (int i = 0; i < 1500; ++i) add(cx + 4 * u(*rng), cy + 1.8 * u(*rng), -1.7 + 1.5 * u(*rng));
  }
  for (int k = 0; k < 10; ++k)  // poles
    for (int i = 0; i < 300; ++i) add(-35 + 7 * k + 0.1 * u(*rng), 9 + 0.1 * u(*rng), -1.7 + 4 * u(*rng));
  return c;
}

}  // namespace test
}  // namespace ret3d
