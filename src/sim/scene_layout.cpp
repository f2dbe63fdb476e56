#include <algorithm>
#include <cmath>
#include <utility>

#include "ret3d/sim/scene.h"
#include "scene_shapes.h"

namespace ret3d {
namespace sim {

namespace {

using namespace detail;

using Straights = std::vector<std::pair<double, double>>;  // station intervals of the main road's straight pieces

// Replay: the main road follows the ego's path, extended straight by the margin at both ends, at the height of the
// ego's ground along it (road_z) when given.
void followEgoPath(Scene& scene, const RoadConfig& rc, const std::vector<V2>& ego_path,
                   const std::vector<double>* road_z, Road& main) {
  std::vector<V2> pts;
  const V2 d0 = (ego_path[1] - ego_path[0]).normalized();
  const V2 d1 = (ego_path.back() - ego_path[ego_path.size() - 2]).normalized();
  for (int k = static_cast<int>(rc.margin); k >= 1; --k) pts.push_back(ego_path[0] - k * d0);
  for (const auto& p : ego_path) pts.push_back(p);
  for (int k = 1; k <= static_cast<int>(rc.margin); ++k) pts.push_back(ego_path.back() + k * d1);
  main.center = Path(pts).slice(0, Path(pts).length(), 1.0);
  scene.ego_start = rc.margin;
  main.z.assign(main.center.points().size(), 0.0);
  if (!road_z || road_z->empty()) return;
  // Road height along the ego path (the ego's ground), held constant beyond its ends.
  Path ego(ego_path);
  for (std::size_t i = 0; i < main.center.points().size(); ++i) {
    const double s = ego.project(main.center.points()[i]);
    const auto& st = ego.stations();
    const std::size_t j = std::min<std::size_t>(
        static_cast<std::size_t>(std::lower_bound(st.begin(), st.end(), s) - st.begin()), road_z->size() - 1);
    main.z[i] = (*road_z)[j];
    if (main.z[i] != 0.0) scene.flat = false;
  }
}

// A drawn main road: a straight run through the ego start (so the first frames are not on a bend), then arcs and
// straights drawn from the config until margin + reach + margin metres. Returns its straight pieces.
Straights drawMainRoad(Scene& scene, const RoadConfig& rc, Rng& rng, double reach, Road& main) {
  Straights straights;
  const double total = 2 * rc.margin + reach;
  std::vector<V2> pts{V2(-rc.margin, 0)};
  double yaw = 0, s = 0;
  auto straight = [&](double len) {
    const double s0 = s;
    for (int k = 1; k <= static_cast<int>(std::round(len)); ++k) pts.push_back(pts.back() + dir(yaw));
    s += std::round(len);
    straights.emplace_back(s0, s);
  };
  straight(rc.margin + 30);
  while (s < total) {
    if (rng.chance(rc.curve_probability)) {
      const double R = draw(rng, rc.curve_radius);
      const double a = draw(rng, rc.curve_angle_deg) * M_PI / 180.0 * (rng.chance(0.5) ? 1 : -1);
      const auto arc = arcPoints(pts.back(), yaw, R, a, 1.0);
      pts.insert(pts.end(), arc.begin(), arc.end());
      s += std::abs(a) * R;
      yaw += a;
    } else {
      straight(draw(rng, rc.segment_length));
    }
  }
  main.center = Path(pts).slice(0, Path(pts).length(), 1.0);
  main.z.assign(main.center.points().size(), 0.0);
  scene.ego_start = rc.margin;
  if (rc.hill_amplitude.hi > 0) {  // drawn only for hills, so that flat scenes keep their random sequence
    const double amplitude = draw(rng, rc.hill_amplitude), wavelength = draw(rng, rc.hill_wavelength);
    const double phase = rng.uniform(0, 2 * M_PI);
    const auto& st = main.center.stations();
    for (std::size_t i = 0; i < main.z.size(); ++i)
      main.z[i] = amplitude * std::sin(2 * M_PI * st[i] / wavelength + phase);
    scene.flat = amplitude == 0.0;
  }
  return straights;
}

// One intersection at station st of the main road: its cross road and the crossings on both sides of it.
void addIntersection(Scene& scene, const SimConfig& config, Rng& rng, double st, double cross_half) {
  const RoadConfig& rc = config.road;
  Intersection in;
  in.s_main = st;
  const PathPose pp = scene.roads[0].center.at(st);
  in.center = pp.p;
  in.light_phase = rng.uniform(0, std::max(config.traffic.traffic_light_cycle, 1.0));
  Road cross;
  cross.half_width = roadHalfWidth(rc, false);
  cross.sidewalk = rc.sidewalk_width;
  const V2 n = normalLeft(pp.yaw);
  std::vector<V2> cp;
  for (double w = -rc.cross_road_length; w <= rc.cross_road_length + 1e-9; w += 1.0) cp.push_back(pp.p + w * n);
  cross.center = Path(cp);
  cross.z.assign(cp.size(), scene.baseHeight(pp.p));
  in.cross_road = static_cast<int>(scene.roads.size());
  scene.roads.push_back(cross);
  scene.intersections.push_back(in);
  scene.crossings.push_back(st - (cross_half + 1.5));
  scene.crossings.push_back(st + (cross_half + 1.5));
}

// Intersections on straight pieces, the first soon ahead of the ego (or, half of the time, one behind the start, so
// the ego may begin after a junction).
void addIntersections(Scene& scene, const SimConfig& config, Rng& rng, const Straights& straights) {
  const RoadConfig& rc = config.road;
  if (rc.intersection_spacing.hi <= 0 || straights.empty()) return;
  const double main_length = scene.roads[0].center.length();  // (roads grows below: no reference into it)
  const double cross_half = roadHalfWidth(rc, false) + rc.sidewalk_width;
  double next = scene.ego_start + rng.uniform(25, 70) - draw(rng, rc.intersection_spacing) * rng.uniform(0, 1) * 0.0;
  if (rng.chance(0.5)) next = scene.ego_start - rng.uniform(20, 60);
  for (const auto& [a, b] : straights) {
    double st = std::max(next, a + cross_half + 15);
    while (st <= b - cross_half - 15 && st < main_length - rc.margin * 0.3) {
      addIntersection(scene, config, rng, st, cross_half);
      st += draw(rng, rc.intersection_spacing);
      next = st;
    }
    next = std::max(next, b);
  }
}

// Mid-block crosswalks ahead of and behind the ego start, none within 35 m of an intersection.
void addMidBlockCrossings(Scene& scene, const RoadConfig& rc, Rng& rng) {
  if (rc.crosswalk_spacing <= 0 || rc.sidewalk_width <= 0) return;
  auto nearIntersection = [&](double st) {
    bool near = false;
    for (const auto& in : scene.intersections) near = near || std::abs(in.s_main - st) < 35;
    return near;
  };
  for (double st = scene.ego_start + rng.uniform(10, rc.crosswalk_spacing); st < scene.roads[0].center.length() - 30;
       st += rc.crosswalk_spacing * rng.uniform(0.7, 1.3))
    if (!nearIntersection(st)) scene.crossings.push_back(st);
  for (double st = scene.ego_start - rng.uniform(10, rc.crosswalk_spacing); st > 30; st -= rc.crosswalk_spacing)
    if (!nearIntersection(st)) scene.crossings.push_back(st);
}

// Lanes of every road: traffic lanes, bike lane or shoulder, parking lane, two walkways per side.
void addLanes(Scene& scene, const RoadConfig& rc) {
  for (std::size_t r = 0; r < scene.roads.size(); ++r) {
    const Road& road = scene.roads[r];
    const bool is_main = road.main;
    const int lanes = is_main ? rc.lanes_per_direction : 1;
    const double med = is_main ? 0.5 * rc.median_width : 0.0;
    for (int side = -1; side <= 1; side += 2) {
      auto add = [&](Lane::Kind kind, int index, double offset, bool forward) {
        Lane l;
        l.kind = kind;
        l.road = static_cast<int>(r);
        l.index = index;
        l.side = side;
        Path p = road.center.offset(side * offset);
        l.path = std::make_shared<const Path>(forward ? p : p.reversed());
        scene.lanes.push_back(l);
      };
      const bool fwd = side < 0;  // right-hand traffic: the right side runs with the road's stations
      for (int i = 0; i < lanes; ++i) add(Lane::Traffic, i, med + (i + 0.5) * rc.lane_width, fwd);
      const double edge = med + lanes * rc.lane_width;
      if (rc.bike_lane_width > 0) add(Lane::Bike, 0, edge + 0.5 * rc.bike_lane_width, fwd);
      else if (rc.shoulder_width > 0.8) add(Lane::Bike, 0, road.half_width - 0.5 * rc.shoulder_width, fwd);
      if (rc.parking_lane_width > 0) add(Lane::Parking, 0, edge + rc.bike_lane_width + 0.5 * rc.parking_lane_width, fwd);
      if (rc.sidewalk_width >= 3.0) {
        add(Lane::Walk, 0, road.half_width + 1.6, fwd);
        add(Lane::Walk, 1, road.half_width + rc.sidewalk_width - 0.7, !fwd);
      }
    }
  }
}

// Spatial hash of centre-line samples (Scene::buckets).
void indexCentreLines(Scene& scene) {
  std::vector<std::pair<long long, Scene::Sample>> items;
  for (std::size_t r = 0; r < scene.roads.size(); ++r) {
    const auto& pts = scene.roads[r].center.points();
    for (std::size_t i = 0; i < pts.size(); ++i) {
      const long ix = static_cast<long>(std::floor(pts[i].x() / scene.cell)), iy = static_cast<long>(std::floor(pts[i].y() / scene.cell));
      items.push_back({static_cast<long long>((static_cast<unsigned long long>(ix) << 32) ^ static_cast<unsigned long long>(iy & 0xffffffff)),
                       {static_cast<int>(r), static_cast<int>(i)}});
    }
  }
  std::stable_sort(items.begin(), items.end(), [](const auto& a, const auto& b) { return a.first < b.first; });
  for (const auto& [key, smp] : items) {
    if (scene.buckets.empty() || scene.buckets.back().first != key) scene.buckets.push_back({key, {}});
    scene.buckets.back().second.push_back(smp);
  }
}

}  // namespace

void layoutRoads(Scene& scene, const SimConfig& config, Rng& rng, double reach, const std::vector<V2>* ego_path,
                 const std::vector<double>* road_z) {
  const RoadConfig& rc = config.road;
  scene.config = &config;
  scene.noise_seed = rng.next();
  scene.terrain_slope[0] = rng.uniform(-1, 1) * config.ground.terrain_slope_max;
  scene.terrain_slope[1] = rng.uniform(-1, 1) * config.ground.terrain_slope_max;
  scene.ego_reach = reach;
  Road main;
  main.main = true;
  main.half_width = roadHalfWidth(rc, true);
  main.sidewalk = rc.sidewalk_width;
  Straights straights;
  if (ego_path && ego_path->size() >= 2)
    followEgoPath(scene, rc, *ego_path, road_z, main);
  else
    straights = drawMainRoad(scene, rc, rng, reach, main);
  scene.roads.push_back(main);
  addIntersections(scene, config, rng, straights);
  addMidBlockCrossings(scene, rc, rng);
  std::sort(scene.crossings.begin(), scene.crossings.end());
  addLanes(scene, rc);
  indexCentreLines(scene);
}

}  // namespace sim
}  // namespace ret3d
