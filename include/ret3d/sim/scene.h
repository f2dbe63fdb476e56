// Procedural driving scenes: a main road of straight and curved pieces with perpendicular cross roads at
// intersections, lanes, bike and parking lanes, sidewalks with curbs, a ground heightfield (flat carriageway, gentle
// slopes and roughness beyond), and static clutter (buildings, walls, fences, trees, poles, signs, guard rails,
// median barriers). The static geometry is one triangle mesh, built once per sequence.
#pragma once

#include <memory>
#include <vector>

#include "ret3d/core/types.h"
#include "ret3d/sim/mesh.h"
#include "ret3d/sim/path.h"
#include "ret3d/sim/random.h"
#include "ret3d/sim/sim_config.h"

namespace ret3d {
namespace sim {

struct Road {
  Path center;                  // sampled every metre
  std::vector<double> z;        // road surface height per sample (0 except in replay, where it follows the ego)
  double half_width = 0;        // curb to centre line (m)
  double sidewalk = 0;          // sidewalk width beyond the curb
  bool main = false;
};

// A path actors follow. Traffic lanes run in the direction of travel (right-hand traffic).
struct Lane {
  enum Kind { Traffic, Bike, Parking, Walk };
  Kind kind = Traffic;
  int road = 0;
  int index = 0;                // traffic lane index from the centre; walkways 0 = inner (near the curb), 1 = outer
  int side = -1;                // -1 right of the road's direction, +1 left
  std::shared_ptr<const Path> path;  // in the direction of travel
};

struct Intersection {
  int cross_road = 0;
  double s_main = 0;            // station on the main road
  Eigen::Vector2d center = Eigen::Vector2d::Zero();
  double light_phase = 0;       // s offset of the traffic light cycle
};

// A roadside structure in the static mesh, as built (for tests and statistics).
struct Furniture {
  enum Kind { Trunk, LampPole, SignPole, Post, Bollard, Bicycle };
  Kind kind = Trunk;
  Eigen::Vector2d p = Eigen::Vector2d::Zero();
  double radius = 0;            // of the trunk or pole (bicycle: 0)
  double height = 0;            // top above the ground (trunk: to the crown's base)
};

struct Scene {
  std::vector<Road> roads;      // roads[0] is the main road, the ego's
  std::vector<Lane> lanes;
  std::vector<Intersection> intersections;
  std::vector<double> crossings;  // stations on the main road where pedestrians cross (crosswalks, intersections)
  TriangleMesh mesh;            // all static geometry
  std::vector<Furniture> furniture;  // trunks, poles, posts, bollards and parked bicycles in it
  double ego_start = 0;         // ego's station on the main road at frame 0
  double ego_reach = 0;         // furthest the ego can drive in the sequence
  double terrain_slope[2] = {0, 0};  // right / left of the main road
  std::uint64_t noise_seed = 0;
  bool flat = true;             // road heights all zero (generated scenes)

  // Ground height (m) at (x, y): carriageway, sidewalk base or sloped terrain, plus roughness.
  double groundHeight(double x, double y) const;
  // Signed distance from the nearest carriageway edge (negative on the road) and that road's index.
  double roadDistance(const Eigen::Vector2d& p, int* road = nullptr, double* lateral = nullptr) const;
  // Road surface height (without roughness) near p: the main road's profile at the nearest station.
  double baseHeight(const Eigen::Vector2d& p) const;
  // True when p is on the carriageway of any road other than `except`.
  bool onOtherCarriageway(const Eigen::Vector2d& p, int except, double margin = 0.0) const;

  const SimConfig* config = nullptr;

  // Spatial hash of road centre samples (for roadDistance).
  struct Sample {
    int road;
    int index;
  };
  double cell = 20.0;
  std::vector<std::pair<long long, std::vector<Sample>>> buckets;  // sorted by key
};

// Lays out the roads along which the ego drives `reach` metres. With `ego_path` (replay) the main road follows it,
// and `road_z` gives the road height along it; otherwise it is drawn from the config.
void layoutRoads(Scene& scene, const SimConfig& config, Rng& rng, double reach,
                 const std::vector<Eigen::Vector2d>* ego_path = nullptr, const std::vector<double>* road_z = nullptr);

// Builds the static mesh: ground heightfield within `view_range` of the ego's route, markings, sidewalks and curbs,
// clutter. Nothing is placed on the footprints in `keep_out` (e.g. replayed actors), nor on roads and walkways.
void buildStaticGeometry(Scene& scene, const SimConfig& config, Rng& rng, double view_range,
                         const std::vector<Box>& keep_out);

// A surface of the named material with reflectivity drawn around its mean.
Surface drawSurface(const SimConfig& config, const std::string& material, Rng& rng);

}  // namespace sim
}  // namespace ret3d
