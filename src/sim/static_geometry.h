#pragma once
// Private to the sim layer: what the two builders of Scene::mesh share (static_geometry.cpp: ground, road surfaces and
// markings; roadside_clutter.cpp: what stands beside the roads).

#include <algorithm>
#include <vector>

#include "ret3d/sim/scene.h"
#include "scene_shapes.h"

namespace ret3d {
namespace sim {
namespace detail {

// The scene being built, its config, the random stream, the boxes to keep clear and the ego's route: only geometry
// within view_range of the route can be seen.
class StaticGeometryBase {
 public:
  StaticGeometryBase(Scene& scene, const SimConfig& config, Rng& rng, double view_range,
                     const std::vector<Box>& keep_out)
      : scene(scene),
        config(config),
        rc(config.road),
        cc(config.clutter),
        rng(rng),
        view_range(view_range),
        keep_out(keep_out),
        mesh(scene.mesh),
        main(scene.roads[0]),
        route(main.center.slice(std::max(0.0, scene.ego_start - 5), scene.ego_start + scene.ego_reach + 5, 2.0)) {}

 protected:
  bool nearRoute(const V2& p, double extra) const {
    // Coarse: distance to the route's 2 m samples.
    for (const auto& q : route.points())
      if ((q - p).squaredNorm() < (view_range + extra) * (view_range + extra)) return true;
    return false;
  }

  Scene& scene;
  const SimConfig& config;
  const RoadConfig& rc;
  const ClutterConfig& cc;
  Rng& rng;
  const double view_range;
  const std::vector<Box>& keep_out;
  TriangleMesh& mesh;
  const Road& main;
  const Path route;
};

// Adds to Scene::mesh (and Scene::furniture) the clutter along both sides of every road; draws from `rng` and from
// streams of its own seeded by the scene.
void buildRoadsideClutter(Scene& scene, const SimConfig& config, Rng& rng, double view_range,
                          const std::vector<Box>& keep_out);

}  // namespace detail
}  // namespace sim
}  // namespace ret3d
