#pragma once
// Private to the sim layer: the small drawing and shape helpers shared by the scene's road layout and its static
// geometry (src/sim/scene_layout.cpp, static_geometry.cpp, roadside_clutter.cpp).

#include <cmath>

#include <Eigen/Geometry>

#include "ret3d/sim/mesh.h"
#include "ret3d/sim/random.h"
#include "ret3d/sim/sim_config.h"

namespace ret3d {
namespace sim {
namespace detail {

using V2 = Eigen::Vector2d;
using V3f = Eigen::Vector3f;

inline double draw(Rng& rng, const Range& r) { return rng.uniform(r.lo, r.hi); }
// A draw only when the range is not a single value, so a fixed size leaves the stream as it was.
inline double drawSized(Rng& rng, const Range& r) { return r.lo < r.hi ? rng.uniform(r.lo, r.hi) : r.lo; }

inline V2 normalLeft(double yaw) { return V2(-std::sin(yaw), std::cos(yaw)); }
inline V2 dir(double yaw) { return V2(std::cos(yaw), std::sin(yaw)); }

inline double roadHalfWidth(const RoadConfig& r, bool main) {
  const int lanes = main ? r.lanes_per_direction : 1;
  return 0.5 * (main ? r.median_width : 0.0) + lanes * r.lane_width + r.bike_lane_width + r.parking_lane_width +
         r.shoulder_width;
}

inline Eigen::Isometry3f poseAt(const V2& p, double z, double yaw) {
  Eigen::Isometry3f T = Eigen::Isometry3f::Identity();
  T.translation() = V3f(static_cast<float>(p.x()), static_cast<float>(p.y()), static_cast<float>(z));
  T.rotate(Eigen::AngleAxisf(static_cast<float>(yaw), V3f::UnitZ()));
  return T;
}

// An upright box between two ground points (walls, barriers, rails): `width` across, from z0 to z1.
inline void addWall(TriangleMesh& mesh, const V2& a, const V2& b, double width, double z0, double z1, Surface s) {
  const V2 d = b - a;
  const double len = d.norm();
  if (len < 1e-3) return;
  const V2 c = 0.5 * (a + b);
  mesh.addBox(poseAt(c, 0.5 * (z0 + z1), std::atan2(d.y(), d.x())),
              V3f(static_cast<float>(len), static_cast<float>(width), static_cast<float>(z1 - z0)), s);
}

}  // namespace detail
}  // namespace sim
}  // namespace ret3d
