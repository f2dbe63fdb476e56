#include <algorithm>
#include <cmath>

#include "static_geometry.h"

namespace ret3d {
namespace sim {

namespace {

using namespace detail;

// Ground, sidewalks with curbs, lane markings, guard rails and zebra crossings near the ego's route. The parts draw
// from `rng` in a fixed order, so a seed gives the same scene.
class RoadSurfaceBuilder : StaticGeometryBase {
 public:
  using StaticGeometryBase::StaticGeometryBase;

  void build() {
    ground();
    roads();
    crossings();
  }

 private:
  // One piece of a road's centre line between two of its samples, with the normals and heights at both ends.
  struct Segment {
    const Road& road;
    std::size_t r, i;
    V2 mid, n0, n1;
    double z0, z1;
  };

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
};

}  // namespace

// Builds Scene::mesh: ground, sidewalks and markings near the ego's route, then the clutter beside every road.
void buildStaticGeometry(Scene& scene, const SimConfig& config, Rng& rng, double view_range,
                         const std::vector<Box>& keep_out) {
  scene.mesh.clear();
  scene.furniture.clear();
  RoadSurfaceBuilder(scene, config, rng, view_range, keep_out).build();
  detail::buildRoadsideClutter(scene, config, rng, view_range, keep_out);
}

}  // namespace sim
}  // namespace ret3d
