#pragma once
// Private to the sim layer: helpers shared by the actors' appearance (actors.cpp), their motion (traffic.cpp) and
// their spawning (traffic_spawn.cpp).

#include <cmath>

#include "ret3d/core/geometry.h"
#include "ret3d/sim/actors.h"
#include "scene_shapes.h"

namespace ret3d {
namespace sim {
namespace detail {

// Paint, glass, tyres, plate, skin, clothing and metal drawn from the config's materials.
ActorSurfaces drawSurfaces(const SimConfig& c, Rng& rng);

// Sets the box (length, width, height, offset) of a pedestrian or cyclist from its mesh and the labellers' habits.
void fitArticulatedBox(Actor& a, Rng& rng);

// Whether two boxes overlap in the bird's-eye view once `a` is grown by `inflate` on every side.
inline bool boxesOverlap(const Box& a, const Box& b, double inflate) {
  const double r = 0.5 * (std::hypot(a.length, a.width) + std::hypot(b.length, b.width)) + inflate;
  if (std::abs(a.x - b.x) > r || std::abs(a.y - b.y) > r) return false;
  Box ai = a;
  ai.length += 2 * inflate;
  ai.width += 2 * inflate;
  return bevIntersectionArea(ai, b) > 1e-9;
}

}  // namespace detail
}  // namespace sim
}  // namespace ret3d
