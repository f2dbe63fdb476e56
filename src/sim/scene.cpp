#include "ret3d/sim/scene.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "ret3d/core/geometry.h"
#include "ret3d/sim/actor_meshes.h"

namespace ret3d {
namespace sim {

namespace {

using V2 = Eigen::Vector2d;
using V3f = Eigen::Vector3f;

double draw(Rng& rng, const Range& r) { return rng.uniform(r.lo, r.hi); }
// A draw only when the range is not a single value, so a fixed size leaves the stream as it was.
double drawSized(Rng& rng, const Range& r) { return r.lo < r.hi ? rng.uniform(r.lo, r.hi) : r.lo; }

V2 normalLeft(double yaw) { return V2(-std::sin(yaw), std::cos(yaw)); }
V2 dir(double yaw) { return V2(std::cos(yaw), std::sin(yaw)); }

// Smooth value noise in [-1, 1] (bilinear between hashed lattice values, smoothstep weights).
double valueNoise(std::uint64_t seed, double x, double y) {
  const double fx = std::floor(x), fy = std::floor(y);
  const auto ix = static_cast<long long>(fx), iy = static_cast<long long>(fy);
  auto h = [&](long long a, long long b) {
    return static_cast<double>(mix64(seed ^ mix64(static_cast<std::uint64_t>(a) * 0x9E3779B1ULL ^
                                                  (static_cast<std::uint64_t>(b) << 32))) >> 11) *
               (2.0 / 9007199254740992.0) - 1.0;
  };
  double tx = x - fx, ty = y - fy;
  tx = tx * tx * (3 - 2 * tx);
  ty = ty * ty * (3 - 2 * ty);
  const double a = h(ix, iy), b = h(ix + 1, iy), c = h(ix, iy + 1), d = h(ix + 1, iy + 1);
  return (a * (1 - tx) + b * tx) * (1 - ty) + (c * (1 - tx) + d * tx) * ty;
}

double roadHalfWidth(const RoadConfig& r, bool main) {
  const int lanes = main ? r.lanes_per_direction : 1;
  return 0.5 * (main ? r.median_width : 0.0) + lanes * r.lane_width + r.bike_lane_width + r.parking_lane_width +
         r.shoulder_width;
}

Eigen::Isometry3f poseAt(const V2& p, double z, double yaw) {
  Eigen::Isometry3f T = Eigen::Isometry3f::Identity();
  T.translation() = V3f(static_cast<float>(p.x()), static_cast<float>(p.y()), static_cast<float>(z));
  T.rotate(Eigen::AngleAxisf(static_cast<float>(yaw), V3f::UnitZ()));
  return T;
}

// An upright box between two ground points (walls, barriers, rails): `width` across, from z0 to z1.
void addWall(TriangleMesh& mesh, const V2& a, const V2& b, double width, double z0, double z1, Surface s) {
  const V2 d = b - a;
  const double len = d.norm();
  if (len < 1e-3) return;
  const V2 c = 0.5 * (a + b);
  mesh.addBox(poseAt(c, 0.5 * (z0 + z1), std::atan2(d.y(), d.x())),
              V3f(static_cast<float>(len), static_cast<float>(width), static_cast<float>(z1 - z0)), s);
}

}  // namespace

Surface drawSurface(const SimConfig& config, const std::string& material, Rng& rng) {
  auto it = config.materials.find(material);
  const MaterialConfig m = it != config.materials.end() ? it->second : MaterialConfig{};
  Surface s;
  s.reflectivity = static_cast<float>(std::clamp(rng.normal(m.reflectivity, m.sigma), 0.01, 1.0));
  s.dropout = static_cast<float>(m.dropout);
  s.porosity = static_cast<float>(m.porosity);
  return s;
}

// ---- queries ------------------------------------------------------------------------------------------------

double Scene::roadDistance(const Eigen::Vector2d& p, int* road, double* lateral) const {
  double best = std::numeric_limits<double>::infinity();
  const long cx = static_cast<long>(std::floor(p.x() / cell)), cy = static_cast<long>(std::floor(p.y() / cell));
  int found_at = -1;
  // Rings of cells outwards; one more ring after the first hit, since a nearer sample may sit there.
  for (int r = 0; r <= 4; ++r) {
    if (found_at >= 0 && r > found_at + 1) break;
    for (long ix = cx - r; ix <= cx + r; ++ix) {
      for (long iy = cy - r; iy <= cy + r; ++iy) {
        if (std::max(std::abs(ix - cx), std::abs(iy - cy)) != r) continue;
        const long long key = static_cast<long long>((static_cast<unsigned long long>(ix) << 32) ^ static_cast<unsigned long long>(iy & 0xffffffff));
        auto it = std::lower_bound(buckets.begin(), buckets.end(), key,
                                   [](const auto& b, long long k) { return b.first < k; });
        if (it == buckets.end() || it->first != key) continue;
        for (const Sample& smp : it->second) {
          const Road& rd = roads[smp.road];
          const auto& pts = rd.center.points();
          // Distance to the segments on both sides of the sample.
          for (int k = std::max(0, smp.index - 1); k <= smp.index && k + 1 < static_cast<int>(pts.size()); ++k) {
            const V2 a = pts[k], d = pts[k + 1] - a;
            const double t = std::clamp((p - a).dot(d) / std::max(d.squaredNorm(), 1e-12), 0.0, 1.0);
            const double dist = (a + t * d - p).norm();
            const double v = dist - rd.half_width;
            if (v < best) {
              best = v;
              if (found_at < 0) found_at = r;
              if (road) *road = smp.road;
              if (lateral) {
                const double cr = d.x() * (p - a).y() - d.y() * (p - a).x();
                *lateral = cr >= 0 ? dist : -dist;
              }
            }
          }
        }
      }
    }
  }
  if (!std::isfinite(best)) {
    best = 4 * cell;  // far from every road
    if (road) *road = 0;
    if (lateral) *lateral = 0;
  }
  return best;
}

double Scene::baseHeight(const Eigen::Vector2d& p) const {
  if (flat || roads.empty() || roads[0].z.empty()) return 0.0;
  const double s = roads[0].center.project(p);
  const auto& st = roads[0].center.stations();
  const std::size_t i = std::min<std::size_t>(static_cast<std::size_t>(std::lower_bound(st.begin(), st.end(), s) - st.begin()),
                                              roads[0].z.size() - 1);
  return roads[0].z[i];
}

bool Scene::onOtherCarriageway(const Eigen::Vector2d& p, int except, double margin) const {
  for (std::size_t r = 0; r < roads.size(); ++r) {
    if (static_cast<int>(r) == except) continue;
    double lat = 0;
    const double s = roads[r].center.project(p, &lat);
    if (s <= 0.0 || s >= roads[r].center.length()) continue;  // beyond the road's ends
    if (std::abs(lat) < roads[r].half_width + margin) return true;
  }
  return false;
}

double Scene::groundHeight(double x, double y) const {
  const SimConfig& c = *config;
  const V2 p(x, y);
  int road = 0;
  double lat = 0;
  const double d = roadDistance(p, &road, &lat);
  const double base = baseHeight(p);
  const double sw = roads.empty() ? 0.0 : roads[road].sidewalk;
  const double lambda = c.ground.roughness_wavelength;
  const double n = valueNoise(noise_seed, x / lambda, y / lambda) + 0.5 * valueNoise(noise_seed + 1, 2 * x / lambda, 2 * y / lambda);
  if (d < 0) return base + c.ground.road_roughness * n / 1.5;
  const double beyond = d - sw - c.ground.terrain_step;
  if (beyond <= 0) return base + c.ground.road_roughness * n / 1.5;
  const double slope = terrain_slope[lat >= 0 ? 1 : 0];
  const double rise = std::clamp(slope * beyond, -1.5, 4.0);
  return base + (sw > 0 ? c.road.curb_height : 0.0) + rise + c.ground.terrain_roughness * n / 1.5;
}

// ---- layout -------------------------------------------------------------------------------------------------

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
  std::vector<std::pair<double, double>> straights;  // station intervals of straight pieces
  if (ego_path && ego_path->size() >= 2) {
    // Replay: the main road follows the ego's path, extended straight by the margin at both ends.
    std::vector<V2> pts;
    const V2 d0 = ((*ego_path)[1] - (*ego_path)[0]).normalized();
    const V2 d1 = (ego_path->back() - (*ego_path)[ego_path->size() - 2]).normalized();
    for (int k = static_cast<int>(rc.margin); k >= 1; --k) pts.push_back((*ego_path)[0] - k * d0);
    for (const auto& p : *ego_path) pts.push_back(p);
    for (int k = 1; k <= static_cast<int>(rc.margin); ++k) pts.push_back(ego_path->back() + k * d1);
    main.center = Path(pts).slice(0, Path(pts).length(), 1.0);
    scene.ego_start = rc.margin;
    main.z.assign(main.center.points().size(), 0.0);
    if (road_z && !road_z->empty()) {
      // Road height along the ego path (the ego's ground), held constant beyond its ends.
      Path ego(*ego_path);
      for (std::size_t i = 0; i < main.center.points().size(); ++i) {
        const double s = ego.project(main.center.points()[i]);
        const auto& st = ego.stations();
        const std::size_t j = std::min<std::size_t>(
            static_cast<std::size_t>(std::lower_bound(st.begin(), st.end(), s) - st.begin()), road_z->size() - 1);
        main.z[i] = (*road_z)[j];
        if (main.z[i] != 0.0) scene.flat = false;
      }
    }
  } else {
    const double total = 2 * rc.margin + reach;
    std::vector<V2> pts{V2(-rc.margin, 0)};
    double yaw = 0, s = 0;
    // A straight run through the ego start, so the first frames are not on a bend.
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
  }
  scene.roads.push_back(main);

  // Intersections on straight pieces, the first soon ahead of the ego.
  if (rc.intersection_spacing.hi > 0 && !straights.empty()) {
    const double cross_half = roadHalfWidth(rc, false) + rc.sidewalk_width;
    double next = scene.ego_start + rng.uniform(25, 70) - draw(rng, rc.intersection_spacing) * rng.uniform(0, 1) * 0.0;
    // Also one behind the start sometimes, so the ego may begin after a junction.
    if (rng.chance(0.5)) next = scene.ego_start - rng.uniform(20, 60);
    for (const auto& [a, b] : straights) {
      double st = std::max(next, a + cross_half + 15);
      while (st <= b - cross_half - 15 && st < main.center.length() - rc.margin * 0.3) {
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
        st += draw(rng, rc.intersection_spacing);
        next = st;
      }
      next = std::max(next, b);
    }
  }
  // Mid-block crosswalks, away from intersections.
  if (rc.crosswalk_spacing > 0 && rc.sidewalk_width > 0) {
    for (double st = scene.ego_start + rng.uniform(10, rc.crosswalk_spacing); st < scene.roads[0].center.length() - 30;
         st += rc.crosswalk_spacing * rng.uniform(0.7, 1.3)) {
      bool near = false;
      for (const auto& in : scene.intersections) near = near || std::abs(in.s_main - st) < 35;
      if (!near) scene.crossings.push_back(st);
    }
    for (double st = scene.ego_start - rng.uniform(10, rc.crosswalk_spacing); st > 30; st -= rc.crosswalk_spacing) {
      bool near = false;
      for (const auto& in : scene.intersections) near = near || std::abs(in.s_main - st) < 35;
      if (!near) scene.crossings.push_back(st);
    }
  }
  std::sort(scene.crossings.begin(), scene.crossings.end());

  // Lanes of every road: traffic lanes, bike lane or shoulder, parking lane, two walkways per side.
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

  // Spatial hash of centre-line samples.
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

// ---- static geometry ----------------------------------------------------------------------------------------

namespace {

bool hitsKeepOut(const std::vector<Box>& keep_out, const Box& b) {
  for (const Box& k : keep_out) {
    if (std::hypot(k.x - b.x, k.y - b.y) > 0.5 * (std::hypot(k.length, k.width) + std::hypot(b.length, b.width)) + 0.5)
      continue;
    Box big = k;
    big.length += 1.0;
    big.width += 1.0;
    if (bevIntersectionArea(big, b) > 0) return true;
  }
  return false;
}

// Footprint clear of every road and sidewalk (by `margin`) and of the keep-out boxes.
bool footprintFree(const Scene& scene, const Box& b, double margin, const std::vector<Box>& keep_out) {
  for (const auto& c : bevCorners(b)) {
    int road = 0;
    const double d = scene.roadDistance(c, &road);
    if (d < scene.roads[road].sidewalk + margin) return false;
  }
  int road = 0;
  if (scene.roadDistance(V2(b.x, b.y), &road) < scene.roads[road].sidewalk + margin) return false;
  return !hitsKeepOut(keep_out, b);
}

// Builds Scene::mesh: ground, sidewalks and markings near the ego's route, then the clutter beside every road. The
// parts draw from `rng` (and the clutter's `extra` stream) in a fixed order, so a seed gives the same scene.
class StaticGeometryBuilder {
 public:
  StaticGeometryBuilder(Scene& scene, const SimConfig& config, Rng& rng, double view_range,
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
        // The ego's route: only geometry within view_range of it can be seen.
        route(main.center.slice(std::max(0.0, scene.ego_start - 5), scene.ego_start + scene.ego_reach + 5, 2.0)) {}

  void build() {
    mesh.clear();
    scene.furniture.clear();
    ground();
    roads();
    crossings();
    clutter();
  }

 private:
  // One piece of a road's centre line between two of its samples, with the normals and heights at both ends.
  struct Segment {
    const Road& road;
    std::size_t r, i;
    V2 mid, n0, n1;
    double z0, z1;
  };

  bool nearRoute(const V2& p, double extra) const {
    // Coarse: distance to the route's 2 m samples.
    for (const auto& q : route.points())
      if ((q - p).squaredNorm() < (view_range + extra) * (view_range + extra)) return true;
    return false;
  }

  void ground() {
    // Ground heightfield over the bounding box of the route plus view range, cells beyond view range skipped.
    Eigen::AlignedBox2d bb;
    for (const auto& q : route.points()) bb.extend(q);
    bb.min() -= V2(view_range, view_range);
    bb.max() += V2(view_range, view_range);
    double cell = config.ground.grid_cell;
    while ((bb.sizes().x() / cell) * (bb.sizes().y() / cell) > 1.2e6) cell *= 1.5;  // keep the mesh bounded
    const int nx = static_cast<int>(std::ceil(bb.sizes().x() / cell)) + 1;
    const int ny = static_cast<int>(std::ceil(bb.sizes().y() / cell)) + 1;
    // Distance from each grid column band to the route, so that far cells are skipped cheaply: a coarse raster.
    const double coarse = 10.0;
    const int cx = static_cast<int>(std::ceil(bb.sizes().x() / coarse)) + 1, cy = static_cast<int>(std::ceil(bb.sizes().y() / coarse)) + 1;
    std::vector<char> keep(static_cast<std::size_t>(cx) * cy, 0);
    for (const auto& q : route.points()) {
      const int r = static_cast<int>(std::ceil((view_range + 15) / coarse));
      const int qx = static_cast<int>((q.x() - bb.min().x()) / coarse), qy = static_cast<int>((q.y() - bb.min().y()) / coarse);
      for (int ix = std::max(0, qx - r); ix <= std::min(cx - 1, qx + r); ++ix)
        for (int iy = std::max(0, qy - r); iy <= std::min(cy - 1, qy + r); ++iy) {
          const V2 c = bb.min() + V2((ix + 0.5) * coarse, (iy + 0.5) * coarse);
          if ((c - q).norm() < view_range + 15) keep[static_cast<std::size_t>(ix) * cy + iy] = 1;
        }
    }
    std::vector<float> height(static_cast<std::size_t>(nx) * ny, 0.0f);
    std::vector<float> dist(static_cast<std::size_t>(nx) * ny, 0.0f);
    std::vector<std::uint32_t> vid(static_cast<std::size_t>(nx) * ny, 0xffffffffu);
    auto cellKept = [&](int i, int j) {
      const int ix = static_cast<int>(i * cell / coarse), iy = static_cast<int>(j * cell / coarse);
      return keep[static_cast<std::size_t>(std::min(ix, cx - 1)) * cy + std::min(iy, cy - 1)] != 0;
    };
    for (int i = 0; i < nx; ++i) {
      for (int j = 0; j < ny; ++j) {
        // A vertex is needed when any of its four cells is kept.
        bool need = false;
        for (int di = -1; di <= 0 && !need; ++di)
          for (int dj = -1; dj <= 0 && !need; ++dj)
            if (i + di >= 0 && j + dj >= 0 && i + di < nx - 1 && j + dj < ny - 1) need = cellKept(i + di, j + dj);
        if (!need) continue;
        const double x = bb.min().x() + i * cell, y = bb.min().y() + j * cell;
        const std::size_t k = static_cast<std::size_t>(i) * ny + j;
        height[k] = static_cast<float>(scene.groundHeight(x, y));
        dist[k] = static_cast<float>(scene.roadDistance(V2(x, y)));
        vid[k] = static_cast<std::uint32_t>(mesh.vertices.size());
        mesh.vertices.emplace_back(static_cast<float>(x), static_cast<float>(y), height[k]);
      }
    }
    for (int i = 0; i + 1 < nx; ++i) {
      for (int j = 0; j + 1 < ny; ++j) {
        if (!cellKept(i, j)) continue;
        const std::size_t a = static_cast<std::size_t>(i) * ny + j, b = a + ny, c = a + ny + 1, d = a + 1;
        if (vid[a] == 0xffffffffu || vid[b] == 0xffffffffu || vid[c] == 0xffffffffu || vid[d] == 0xffffffffu) continue;
        const double dm = 0.25 * (dist[a] + dist[b] + dist[c] + dist[d]);
        const char* mat = dm < 0 ? "asphalt" : (dm < rc.sidewalk_width ? "concrete" : "terrain");
        const Surface s = drawSurface(config, mat, rng);
        mesh.triangles.push_back({vid[a], vid[b], vid[c]});
        mesh.triangles.push_back({vid[a], vid[c], vid[d]});
        mesh.surfaces.push_back(s);
        mesh.surfaces.push_back(s);
      }
    }
  }

  // Sidewalks with curbs, and lane markings, on every road near the route.
  void roads() {
    for (std::size_t r = 0; r < scene.roads.size(); ++r) {
      const Road& road = scene.roads[r];
      const auto& pts = road.center.points();
      for (std::size_t i = 0; i + 1 < pts.size(); ++i) {
        const V2 mid = 0.5 * (pts[i] + pts[i + 1]);
        if (!nearRoute(mid, 20)) continue;
        const double yaw0 = road.center.at(road.center.stations()[i]).yaw;
        const double yaw1 = road.center.at(road.center.stations()[i + 1]).yaw;
        const Segment seg{road, r, i, mid, normalLeft(yaw0), normalLeft(yaw1), road.z.empty() ? 0.0 : road.z[i],
                          road.z.empty() ? 0.0 : road.z[i + 1]};
        if (road.sidewalk > 0) sidewalks(seg);
        markings(seg);
        guardRails(seg);
      }
    }
  }

  void sidewalks(const Segment& seg) {
    const Road& road = seg.road;
    const auto& pts = road.center.points();
    const std::size_t r = seg.r, i = seg.i;
    const double W = road.half_width;
    const V2 n0 = seg.n0, n1 = seg.n1;
    const double z0 = seg.z0, z1 = seg.z1;
    for (int side = -1; side <= 1; side += 2) {
      const V2 a0 = pts[i] + side * W * n0, a1 = pts[i + 1] + side * W * n1;
      const V2 b0 = pts[i] + side * (W + road.sidewalk) * n0, b1 = pts[i + 1] + side * (W + road.sidewalk) * n1;
      if (scene.onOtherCarriageway(0.5 * (a0 + a1), static_cast<int>(r), 0.2) ||
          scene.onOtherCarriageway(0.5 * (b0 + b1), static_cast<int>(r), 0.2))
        continue;
      const float h = static_cast<float>(rc.curb_height);
      auto v = [](const V2& p, double z) { return V3f(static_cast<float>(p.x()), static_cast<float>(p.y()), static_cast<float>(z)); };
      const Surface top = drawSurface(config, "concrete", rng), curb = drawSurface(config, "curb", rng);
      mesh.addQuad(v(a0, z0 + h), v(a1, z1 + h), v(b1, z1 + h), v(b0, z0 + h), top);
      mesh.addQuad(v(a0, z0 - 0.1), v(a1, z1 - 0.1), v(a1, z1 + h), v(a0, z0 + h), curb);
      mesh.addQuad(v(b0, z0 - 0.1), v(b1, z1 - 0.1), v(b1, z1 + h), v(b0, z0 + h), curb);
    }
  }

  void markings(const Segment& seg) {
    const Road& road = seg.road;
    const auto& pts = road.center.points();
    const std::size_t r = seg.r, i = seg.i;
    const V2 mid = seg.mid, n0 = seg.n0, n1 = seg.n1;
    const double z0 = seg.z0;
    // Markings: centre line (dashed) or median barrier, lane dividers (dashed), edge lines (solid).
    const double s = road.center.stations()[i];
    const bool dash_on = std::fmod(s, rc.marking_dash + rc.marking_gap) < rc.marking_dash;
    const int lanes = road.main ? rc.lanes_per_direction : 1;
    const double med = road.main ? 0.5 * rc.median_width : 0.0;
    std::vector<std::pair<double, double>> lines;  // (offset, width)
    if (road.main && rc.median_width > 0) {
      const Surface conc = drawSurface(config, "concrete", rng);
      if (!scene.onOtherCarriageway(mid, static_cast<int>(r), 0.0))
        addWall(mesh, pts[i], pts[i + 1], 0.6, z0 - 0.05, z0 + 0.85, conc);
    } else if (dash_on) {
      lines.emplace_back(0.0, 0.12);
    }
    for (int side = -1; side <= 1; side += 2) {
      for (int l = 1; l < lanes; ++l)
        if (dash_on) lines.emplace_back(side * (med + l * rc.lane_width), 0.12);
      if (rc.bike_lane_width + rc.parking_lane_width + rc.shoulder_width > 0)
        lines.emplace_back(side * (med + lanes * rc.lane_width), 0.15);
      if (road.main && rc.median_width > 0) lines.emplace_back(side * (med + 0.3), 0.15);
    }
    if (scene.onOtherCarriageway(mid, static_cast<int>(r), 0.5)) lines.clear();
    const Surface paint = drawSurface(config, "marking", rng);
    for (const auto& [off, w] : lines) {
      const V2 p0 = pts[i] + (off - 0.5 * w) * n0, p1 = pts[i + 1] + (off - 0.5 * w) * n1;
      const V2 q0 = pts[i] + (off + 0.5 * w) * n0, q1 = pts[i + 1] + (off + 0.5 * w) * n1;
      auto v = [&](const V2& p) {
        return V3f(static_cast<float>(p.x()), static_cast<float>(p.y()), static_cast<float>(scene.groundHeight(p.x(), p.y()) + 0.006));
      };
      mesh.addQuad(v(p0), v(p1), v(q1), v(q0), paint);
    }
  }

  void guardRails(const Segment& seg) {
    const Road& road = seg.road;
    const auto& pts = road.center.points();
    const std::size_t r = seg.r, i = seg.i;
    const double W = road.half_width;
    const V2 n0 = seg.n0;
    const double z0 = seg.z0;
    // Guard rails along the outer edge (highway).
    if (cc.guard_rail > 0.5 && i % 2 == 0) {
      const Surface metal = drawSurface(config, "metal", rng);
      for (int side = -1; side <= 1; side += 2) {
        const V2 g0 = pts[i] + side * (W + 0.5) * n0, g1 = pts[std::min(i + 2, pts.size() - 1)] + side * (W + 0.5) * normalLeft(road.center.at(road.center.stations()[std::min(i + 2, pts.size() - 1)]).yaw);
        if (scene.onOtherCarriageway(g0, static_cast<int>(r), 0.5)) continue;
        mesh.addBeam(V3f(static_cast<float>(g0.x()), static_cast<float>(g0.y()), static_cast<float>(z0 - 0.1)),
                     V3f(static_cast<float>(g0.x()), static_cast<float>(g0.y()), static_cast<float>(z0 + 0.75)), 0.12f, metal);
        addWall(mesh, g0, g1, 0.08, z0 + 0.45, z0 + 0.75, metal);
      }
    }
  }

  // Zebra crossings on the main road.
  void crossings() {
    for (double sc : scene.crossings) {
      const PathPose pp = main.center.at(sc);
      if (!nearRoute(pp.p, 20)) continue;
      const V2 t = dir(pp.yaw), n = normalLeft(pp.yaw);
      const double w = main.half_width - rc.parking_lane_width - 0.3;
      const Surface paint = drawSurface(config, "marking", rng);
      for (double o = -w; o + 0.5 <= w; o += 1.0) {
        V2 c[4] = {pp.p - 1.5 * t + o * n, pp.p + 1.5 * t + o * n, pp.p + 1.5 * t + (o + 0.5) * n, pp.p - 1.5 * t + (o + 0.5) * n};
        V3f v[4];
        for (int k = 0; k < 4; ++k)
          v[k] = V3f(static_cast<float>(c[k].x()), static_cast<float>(c[k].y()), static_cast<float>(scene.groundHeight(c[k].x(), c[k].y()) + 0.006));
        mesh.addQuad(v[0], v[1], v[2], v[3], paint);
      }
    }
  }

  // Clutter along both sides of every road: buildings with windows, walls or fences in the gaps, trees, poles, signs.
  void clutter() {
    Rng extra(mix64(scene.noise_seed ^ 0x6865646765ULL));   // hedges, bushes, bollards
    Rng street(mix64(scene.noise_seed ^ 0x737472656574ULL));  // posts, bicycles, railings, low walls, sign shapes
    for (std::size_t r = 0; r < scene.roads.size(); ++r) {
      for (int side = -1; side <= 1; side += 2) {
        const Road& road = scene.roads[r];
        frontage(road, side);
        if (cc.hedge_probability > 0) hedges(road, side, extra);
        if (cc.bush_spacing.hi > 0) bushes(road, side, extra);
        if (cc.bollard_spacing.hi > 0 && road.sidewalk > 0) bollards(road, r, side, extra);
        trees(road, r, side);
        polesAndSigns(road, r, side, street);
        if (road.sidewalk <= 0) continue;
        if (cc.post_spacing.hi > 0) posts(road, r, side, street);
        if (cc.bicycle_spacing.hi > 0) bicycles(road, r, side, street);
        if (cc.railing_probability > 0 || cc.low_wall_probability > 0) edges(road, r, side, street);
      }
    }
  }

  // Where a roadside object may stand: near the route, off other carriageways and crossings, outside keep-out boxes.
  bool furnitureSpot(const Road& road, std::size_t r, double s, const V2& p, double size, double crossing) const {
    if (!nearRoute(p, 5) || scene.onOtherCarriageway(p, static_cast<int>(r), 0.5)) return false;
    if (road.main)
      for (double c : scene.crossings)
        if (std::abs(c - s) < crossing) return false;
    Box fb;
    fb.x = p.x();
    fb.y = p.y();
    fb.length = fb.width = size;
    return !hitsKeepOut(keep_out, fb);
  }

  // Thin posts in the furniture zone: parking meters, ticket machines' posts, pipes, short poles.
  void posts(const Road& road, std::size_t r, int side, Rng& st) {
    const double L = road.center.length();
    for (double s = st.uniform(0, cc.post_spacing.hi); s < L; s += std::max(0.5, draw(st, cc.post_spacing))) {
      const PathPose pp = road.center.at(s);
      const V2 p = pp.p + side * (road.half_width + st.uniform(0.3, 1.2)) * normalLeft(pp.yaw);
      const double radius = draw(st, cc.post_radius), h = draw(st, cc.post_height);
      if (!furnitureSpot(road, r, s, p, 0.4, 3)) continue;
      const double z0 = scene.groundHeight(p.x(), p.y()) + rc.curb_height;
      const Surface metal = drawSurface(config, "metal", st);
      mesh.addCylinder(poseAt(p, z0 - 0.1, 0), static_cast<float>(radius), static_cast<float>(h + 0.1), 6, metal);
      // Half of them carry a box (meter, ticket machine, sign) near the top.
      if (st.chance(0.5) && h > 1.1)
        mesh.addBox(poseAt(p, z0 + h - 0.2, pp.yaw), V3f(0.25f, 0.2f, 0.35f), metal);
      scene.furniture.push_back({Furniture::Post, p, radius, h});
    }
  }

  // Groups of 1-4 parked bicycles, across the sidewalk at a rack in the furniture zone or along the building side.
  // Static and unlabelled, as KITTI labels no bicycle without its rider.
  void bicycles(const Road& road, std::size_t r, int side, Rng& st) {
    const double L = road.center.length();
    for (double s = st.uniform(0, cc.bicycle_spacing.hi); s < L; s += std::max(1.0, draw(st, cc.bicycle_spacing))) {
      const PathPose pp = road.center.at(s);
      const V2 n = normalLeft(pp.yaw), t = dir(pp.yaw);
      const bool rack = st.chance(0.6);
      const double off = rack ? road.half_width + 1.2 : road.half_width + road.sidewalk - 0.45;
      const int count = st.integer(1, 4);
      ActorSurfaces surf;
      surf.metal = drawSurface(config, "metal", st);
      surf.tire = drawSurface(config, "tire", st);
      for (int k = 0; k < count; ++k) {
        const V2 p = pp.p + side * off * n + (k * (rack ? 0.75 : 1.9)) * t;
        if (!furnitureSpot(road, r, s + k, p, 1.0, 4)) continue;
        const double yaw = rack ? pp.yaw + M_PI / 2 + st.normal(0, 0.1) : pp.yaw + st.normal(0, 0.1);
        const double z0 = scene.groundHeight(p.x(), p.y()) + rc.curb_height;
        Eigen::Isometry3f T = poseAt(p, z0, yaw);
        T.rotate(Eigen::AngleAxisf(static_cast<float>(st.normal(0, 0.08)), V3f::UnitX()));  // on its stand
        mesh.append(bicycleMesh(st.uniform(1.6, 1.85), st.uniform(0.42, 0.65), surf), T);
        scene.furniture.push_back({Furniture::Bicycle, p, 0.0, 1.05});
      }
    }
  }

  // Pedestrian railings at the kerb (posts every 1.5-2.5 m, a top rail and a mid rail) and low walls or planters at
  // the sidewalk's outer edge, per frontage slot, in 2 m pieces each checked on its own.
  void edges(const Road& road, std::size_t r, int side, Rng& st) {
    const double L = road.center.length();
    for (double s = st.uniform(0, 10); s < L;) {
      const double f = draw(st, cc.building_frontage);
      const bool railing = st.chance(cc.railing_probability), low = st.chance(cc.low_wall_probability);
      const double h_rail = draw(st, cc.railing_height), h_low = draw(st, cc.low_wall_height);
      const double post_step = st.uniform(1.5, 2.5), width = st.uniform(0.2, 0.8);
      const Surface metal = drawSurface(config, "metal", st), stone = drawSurface(config, "concrete", st);
      for (double s0 = s; s0 + 0.5 < s + f; s0 += 2.0) {
        const double s1 = std::min(s0 + 2.0, s + f);
        for (int which = 0; which < 2; ++which) {
          if (!(which == 0 ? railing : low)) continue;
          const double off = which == 0 ? road.half_width + 0.25 : road.half_width + road.sidewalk - 0.5 * width;
          const V2 a = road.center.at(s0).p + side * off * normalLeft(road.center.at(s0).yaw);
          const V2 e = road.center.at(s1).p + side * off * normalLeft(road.center.at(s1).yaw);
          if (!furnitureSpot(road, r, 0.5 * (s0 + s1), 0.5 * (a + e), (e - a).norm(), 4)) continue;
          const double z0 = scene.groundHeight(0.5 * (a.x() + e.x()), 0.5 * (a.y() + e.y())) + rc.curb_height;
          if (which == 1) {
            addWall(mesh, a, e, width, z0 - 0.1, z0 + h_low, stone);
            continue;
          }
          if (std::fmod(s0 - s, post_step) < 2.0)
            mesh.addBeam(V3f(a.x(), a.y(), z0 - 0.1), V3f(a.x(), a.y(), z0 + h_rail), 0.05f, metal);
          for (double rz : {0.5 * h_rail, h_rail - 0.03})
            addWall(mesh, a, e, 0.04, z0 + rz - 0.025, z0 + rz + 0.025, metal);
        }
      }
      s += f + st.uniform(1, 6);
    }
  }

  // Frontage: buildings and gaps.
  void frontage(const Road& road, int side) {
    const double L = road.center.length();
    const double W = road.half_width, SW = road.sidewalk;
    for (double s = rng.uniform(0, 10); s < L;) {
      const double f = draw(rng, cc.building_frontage);
      const PathPose pp = road.center.at(s + 0.5 * f);
      const V2 n = normalLeft(pp.yaw);
      const double setback = draw(rng, cc.building_setback);
      if (nearRoute(pp.p, 30)) {
        if (rng.chance(cc.building_probability)) {
          const double depth = draw(rng, cc.building_depth), height = draw(rng, cc.building_height);
          Box b;
          const V2 c = pp.p + side * (W + SW + setback + 0.5 * depth) * n;
          b.x = c.x();
          b.y = c.y();
          b.length = f;
          b.width = depth;
          b.yaw = pp.yaw;
          if (footprintFree(scene, b, 0.3, keep_out)) {
            const double z0 = scene.baseHeight(c) - 0.5;
            const Surface wall = drawSurface(config, "building", rng);
            mesh.addBox(poseAt(c, z0 + 0.5 * (height + 0.5), pp.yaw), V3f(static_cast<float>(f), static_cast<float>(depth), static_cast<float>(height + 0.5)), wall, false);
            // Windows on the street facade, slightly proud of it.
            const Surface glass = drawSurface(config, "glass", rng);
            const V2 face = c - side * 0.5 * depth * n - side * 0.03 * n;
            const V2 t = dir(pp.yaw);
            for (double fz = 1.0; fz + 1.6 < height; fz += 3.0) {
              for (double fx = -0.5 * f + 1.0; fx + 1.3 < 0.5 * f; fx += 2.6) {
                const V2 a = face + fx * t, bq = face + (fx + 1.3) * t;
                const double zb = z0 + 0.5 + fz;
                mesh.addQuad(V3f(a.x(), a.y(), zb), V3f(bq.x(), bq.y(), zb), V3f(bq.x(), bq.y(), zb + 1.5),
                             V3f(a.x(), a.y(), zb + 1.5), glass);
              }
            }
          }
        } else if (rng.chance(cc.wall_probability)) {
          const double h = draw(rng, cc.wall_height);
          const V2 a = road.center.at(s).p + side * (W + SW + setback) * normalLeft(road.center.at(s).yaw);
          const V2 e = road.center.at(s + f).p + side * (W + SW + setback) * normalLeft(road.center.at(s + f).yaw);
          Box b;
          b.x = 0.5 * (a.x() + e.x());
          b.y = 0.5 * (a.y() + e.y());
          b.length = (e - a).norm();
          b.width = 0.3;
          b.yaw = std::atan2(e.y() - a.y(), e.x() - a.x());
          if (footprintFree(scene, b, 0.2, keep_out)) {
            const double z0 = scene.groundHeight(b.x, b.y);
            if (rng.chance(cc.fence_fraction)) {
              const Surface metal = drawSurface(config, "metal", rng);
              const int posts = std::max(1, static_cast<int>(b.length / 2.5));
              for (int k = 0; k <= posts; ++k) {
                const V2 p = a + (e - a) * (static_cast<double>(k) / posts);
                mesh.addBeam(V3f(p.x(), p.y(), z0 - 0.2), V3f(p.x(), p.y(), z0 + h), 0.07f, metal);
              }
              for (double rz : {0.35 * h, 0.95 * h}) addWall(mesh, a, e, 0.05, z0 + rz - 0.03, z0 + rz + 0.03, metal);
            } else {
              addWall(mesh, a, e, 0.25, z0 - 0.3, z0 + h, drawSurface(config, "building", rng));
            }
          }
        }
      }
      s += f + draw(rng, cc.building_gap);
    }
  }

  // Hedges along the sidewalk's outer edge; hedges, bushes and bollards draw from their own stream (`extra`).
  void hedges(const Road& road, int side, Rng& extra) {
    const double L = road.center.length();
    const double W = road.half_width, SW = road.sidewalk;
    for (double s = extra.uniform(0, 10); s < L;) {
      const double f = draw(extra, cc.building_frontage);
      if (extra.chance(cc.hedge_probability)) {
        const double off = W + SW + 0.6, h = draw(extra, cc.hedge_height), depth = extra.uniform(0.7, 1.2);
        const Surface leaves = drawSurface(config, "foliage", extra);
        // In pieces of about 2 m, each checked on its own, so a hedge stops at cross roads and driveways.
        for (double s0 = s; s0 + 0.5 < s + f; s0 += 2.0) {
          const double s1 = std::min(s0 + 2.0, s + f);
          const V2 a = road.center.at(s0).p + side * off * normalLeft(road.center.at(s0).yaw);
          const V2 e = road.center.at(s1).p + side * off * normalLeft(road.center.at(s1).yaw);
          Box b;
          b.x = 0.5 * (a.x() + e.x());
          b.y = 0.5 * (a.y() + e.y());
          b.length = (e - a).norm();
          b.width = depth;
          b.yaw = std::atan2(e.y() - a.y(), e.x() - a.x());
          if (!nearRoute(V2(b.x, b.y), 5) || !footprintFree(scene, b, 0.0, keep_out)) continue;
          const double z0 = scene.groundHeight(b.x, b.y);
          addWall(mesh, a, e, depth, z0 - 0.1, z0 + h, leaves);
        }
      }
      s += f + extra.uniform(1, 6);
    }
  }

  // Bushes beyond the sidewalk.
  void bushes(const Road& road, int side, Rng& extra) {
    const double L = road.center.length();
    const double W = road.half_width, SW = road.sidewalk;
    for (double s = extra.uniform(0, cc.bush_spacing.hi); s < L; s += std::max(0.5, draw(extra, cc.bush_spacing))) {
      const PathPose pp = road.center.at(s);
      const double r = draw(extra, cc.bush_radius);
      const V2 p = pp.p + side * (W + SW + 0.3 + r + extra.uniform(0, 3)) * normalLeft(pp.yaw);
      Box fb;
      fb.x = p.x();
      fb.y = p.y();
      fb.length = fb.width = 2 * r;
      if (!nearRoute(p, 5) || !footprintFree(scene, fb, 0.1, keep_out)) continue;
      const double z0 = scene.groundHeight(p.x(), p.y());
      mesh.addEllipsoid(poseAt(p, z0 + 0.6 * r, extra.uniform(0, M_PI)),
                        V3f(static_cast<float>(r), static_cast<float>(r * extra.uniform(0.6, 1.0)),
                            static_cast<float>(0.8 * r)),
                        8, 5, drawSurface(config, "foliage", extra));
    }
  }

  // Bollards at the curb, none near a zebra crossing.
  void bollards(const Road& road, std::size_t r, int side, Rng& extra) {
    const double L = road.center.length();
    const double W = road.half_width;
    for (double s = extra.uniform(0, cc.bollard_spacing.hi); s < L;
         s += std::max(0.5, draw(extra, cc.bollard_spacing))) {
      const PathPose pp = road.center.at(s);
      const V2 p = pp.p + side * (W + 0.3) * normalLeft(pp.yaw);
      Box fb;
      fb.x = p.x();
      fb.y = p.y();
      fb.length = fb.width = 0.3;
      bool at_crossing = false;
      if (road.main)
        for (double c : scene.crossings) at_crossing = at_crossing || std::abs(c - s) < 4;
      if (at_crossing || !nearRoute(p, 5) || scene.onOtherCarriageway(p, static_cast<int>(r), 0.5) ||
          hitsKeepOut(keep_out, fb))
        continue;
      const double z0 = scene.groundHeight(p.x(), p.y()) + rc.curb_height;
      const double h = draw(extra, cc.bollard_height), radius = drawSized(extra, cc.bollard_radius);
      mesh.addCylinder(poseAt(p, z0 - 0.1, 0), static_cast<float>(radius), static_cast<float>(0.1 + h), 6,
                       drawSurface(config, "metal", extra));
      scene.furniture.push_back({Furniture::Bollard, p, radius, h});
    }
  }

  // Trees.
  void trees(const Road& road, std::size_t r, int side) {
    const double L = road.center.length();
    const double W = road.half_width, SW = road.sidewalk;
    for (double s = rng.uniform(0, cc.tree_spacing.hi); s < L; s += draw(rng, cc.tree_spacing)) {
      const PathPose pp = road.center.at(s);
      const bool furniture = SW >= 3.0 && cc.vegetation_setback <= 0;
      const double off = furniture ? W + 0.65 : W + SW + cc.vegetation_setback + rng.uniform(0, 12);
      const V2 p = pp.p + side * off * normalLeft(pp.yaw);
      if (!nearRoute(p, 10) || scene.onOtherCarriageway(p, static_cast<int>(r), SW + 1.0)) continue;
      bool at_crossing = false;
      if (road.main)
        for (double c : scene.crossings) at_crossing = at_crossing || std::abs(c - s) < 4;
      if (at_crossing) continue;
      Box fb;
      fb.x = p.x();
      fb.y = p.y();
      fb.length = fb.width = 0.8;
      if (hitsKeepOut(keep_out, fb)) continue;
      if (!furniture) {
        int rr = 0;
        if (scene.roadDistance(p, &rr) < scene.roads[rr].sidewalk + 1.0) continue;
      }
      const double z0 = scene.groundHeight(p.x(), p.y());
      const double tr = draw(rng, cc.tree_trunk_radius), th = draw(rng, cc.tree_trunk_height);
      const double cr = draw(rng, cc.tree_crown_radius);
      mesh.addCylinder(poseAt(p, z0 - 0.2, 0), static_cast<float>(tr), static_cast<float>(th + 0.2 + 0.3 * cr), 7,
                       drawSurface(config, "bark", rng));
      scene.furniture.push_back({Furniture::Trunk, p, tr, th});
      mesh.addEllipsoid(poseAt(p, z0 + th + 0.85 * cr, rng.uniform(0, M_PI)),
                        V3f(static_cast<float>(cr), static_cast<float>(cr * rng.uniform(0.8, 1.0)), static_cast<float>(cr * rng.uniform(0.8, 1.2))),
                        10, 6, drawSurface(config, "foliage", rng));
    }
  }

  // Street lights and signs in the furniture zone (or on the shoulder's edge).
  void polesAndSigns(const Road& road, std::size_t r, int side, Rng& st) {
    const double L = road.center.length();
    const double W = road.half_width, SW = road.sidewalk;
    for (int kind = 0; kind < 2; ++kind) {
      const Range spacing = kind == 0 ? cc.pole_spacing : cc.sign_spacing;
      for (double s = rng.uniform(0, spacing.hi); s < L; s += draw(rng, spacing)) {
        const PathPose pp = road.center.at(s);
        const V2 n = normalLeft(pp.yaw);
        const V2 p = pp.p + side * (W + (SW > 0 ? 0.35 : 1.2)) * n;
        if (!nearRoute(p, 10) || scene.onOtherCarriageway(p, static_cast<int>(r), SW + 0.5)) continue;
        bool at_crossing = false;
        if (road.main)
          for (double c : scene.crossings) at_crossing = at_crossing || std::abs(c - s) < 3;
        Box fb;
        fb.x = p.x();
        fb.y = p.y();
        fb.length = fb.width = 0.5;
        if (at_crossing || hitsKeepOut(keep_out, fb)) continue;
        const double z0 = scene.groundHeight(p.x(), p.y()) + (SW > 0 ? rc.curb_height : 0.0);
        const Surface metal = drawSurface(config, "metal", rng);
        if (kind == 0) {
          const double h = draw(rng, cc.pole_height), radius = drawSized(rng, cc.pole_radius);
          mesh.addCylinder(poseAt(p, z0 - 0.2, 0), static_cast<float>(radius), static_cast<float>(h + 0.2), 6, metal);
          const V2 arm = p - side * 1.5 * n;
          mesh.addBeam(V3f(p.x(), p.y(), z0 + h - 0.1), V3f(arm.x(), arm.y(), z0 + h), 0.08f, metal);
          mesh.addBox(poseAt(arm, z0 + h - 0.1, pp.yaw), V3f(0.5f, 0.3f, 0.15f), metal);
          scene.furniture.push_back({Furniture::LampPole, p, radius, h});
        } else {
          const double top = drawSized(rng, cc.sign_height), side_len = drawSized(rng, cc.sign_plate);
          mesh.addCylinder(poseAt(p, z0 - 0.2, 0), 0.04f, static_cast<float>(top + 0.2), 5, metal);
          // Plates facing the traffic of this side: one, or (from the street stream, when plates vary) a wider one
          // or a second below it.
          const V2 t = dir(pp.yaw) * (side < 0 ? 1.0 : -1.0);
          const V2 c = p + 0.06 * t;
          const V2 q = V2(-t.y(), t.x());
          const Surface sign = drawSurface(config, "sign", rng);
          const bool vary = cc.sign_plate.lo < cc.sign_plate.hi;
          const double hw = 0.5 * side_len * (vary && st.chance(0.3) ? 1.5 : 1.0), hh = 0.5 * side_len;
          const int plates = vary && st.chance(0.3) ? 2 : 1;
          for (int k = 0; k < plates; ++k) {
            const double zc = z0 + top - 0.1 - k * (2 * hh + 0.1);
            mesh.addQuad(V3f(c.x() - hw * q.x(), c.y() - hw * q.y(), zc - hh), V3f(c.x() + hw * q.x(), c.y() + hw * q.y(), zc - hh),
                         V3f(c.x() + hw * q.x(), c.y() + hw * q.y(), zc + hh), V3f(c.x() - hw * q.x(), c.y() - hw * q.y(), zc + hh), sign);
          }
          scene.furniture.push_back({Furniture::SignPole, p, 0.04, top});
        }
      }
    }
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

}  // namespace

void buildStaticGeometry(Scene& scene, const SimConfig& config, Rng& rng, double view_range,
                         const std::vector<Box>& keep_out) {
  StaticGeometryBuilder(scene, config, rng, view_range, keep_out).build();
}

}  // namespace sim
}  // namespace ret3d
