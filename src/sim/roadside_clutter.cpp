#include <algorithm>
#include <cmath>

#include "ret3d/core/geometry.h"
#include "ret3d/sim/actor_meshes.h"
#include "static_geometry.h"

namespace ret3d {
namespace sim {
namespace detail {

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

// Buildings with windows, walls or fences in the gaps, hedges, bushes, bollards, trees, poles, signs, posts and parked
// bicycles along both sides of every road.
class RoadsideClutterBuilder : StaticGeometryBase {
 public:
  using StaticGeometryBase::StaticGeometryBase;

  void build() { clutter(); }

 private:
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
};

}  // namespace

void buildRoadsideClutter(Scene& scene, const SimConfig& config, Rng& rng, double view_range,
                          const std::vector<Box>& keep_out) {
  RoadsideClutterBuilder(scene, config, rng, view_range, keep_out).build();
}

}  // namespace detail
}  // namespace sim
}  // namespace ret3d
