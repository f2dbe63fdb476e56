#include <algorithm>
#include <cmath>

#include "actor_internal.h"
#include "ret3d/core/geometry.h"
#include "ret3d/sim/actors.h"

namespace ret3d {
namespace sim {

namespace {
using V2 = Eigen::Vector2d;
}  // namespace

using detail::boxesOverlap;
using detail::draw;
using detail::drawSurfaces;
using detail::fitArticulatedBox;

namespace {

// Coarse: distance to the route's samples.
bool nearRoute(const Path& route, const V2& p, double r) {
  for (const auto& q : route.points())
    if ((q - p).squaredNorm() < r * r) return true;
  return false;
}

}  // namespace

void Traffic::spawn(Rng& rng, double view_range) {
  spawnEgo(rng);
  if (config_.traffic.queue.probability > 0 && rng.chance(config_.traffic.queue.probability)) spawnQueues(rng);
  const Road& main = scene_.roads[0];
  const Path route = main.center.slice(std::max(0.0, scene_.ego_start - 5), scene_.ego_start + scene_.ego_reach + 5, 4.0);
  for (const Lane& l : scene_.lanes) {
    if (l.kind == Lane::Parking) {
      if (l.road != 0 && !rng.chance(config_.traffic.parked_on_cross_roads)) continue;
      spawnParked(l, route, view_range, rng);
    } else if (l.kind == Lane::Traffic) {
      spawnCars(l, rng);
    } else if (l.kind == Lane::Bike) {
      spawnCyclists(l, route, view_range, rng);
    } else if (l.kind == Lane::Walk) {
      spawnPedestrians(l, route, view_range, rng);
    }
  }
}

// The ego: a mid-size car in a lane of the main road's forward direction.
void Traffic::spawnEgo(Rng& rng) {
  const TrafficConfig& tc = config_.traffic;
  std::vector<const Lane*> ego_lanes;
  for (const Lane& l : scene_.lanes)
    if (l.road == 0 && l.kind == Lane::Traffic && l.side < 0) ego_lanes.push_back(&l);
  int lane = tc.ego_lane >= 0 ? std::min(static_cast<int>(tc.ego_lane), static_cast<int>(ego_lanes.size()) - 1)
                              : rng.integer(0, static_cast<int>(ego_lanes.size()) - 1);
  ego = Actor();
  ego.kind = ActorKind::Car;
  ego.labelled = false;
  ego.length = 4.7;
  ego.width = 1.82;
  ego.height = 1.5;
  ego.path = ego_lanes[lane]->path;
  ego.s = scene_.ego_start;
  ego.v_cruise = ego.v_target = draw(rng, tc.ego_speed);
  ego.v = ego.v_target;
  ego.next_change = draw(rng, tc.speed_change_interval);
  findStops(ego);
  place(ego);
  ego_pose_ = Eigen::Isometry3d::Identity();
  ego_pose_.translation() = Eigen::Vector3d(ego.x, ego.y, ego.z);
  ego_pose_.linear() = Eigen::AngleAxisd(ego.yaw, Eigen::Vector3d::UnitZ()).toRotationMatrix();
}

void Traffic::spawnQueues(Rng& rng) {
  const QueueConfig& q = config_.traffic.queue;
  ego.queued = true;
  ego.v = 0;
  ego.jam_gap = draw(rng, q.gap);
  for (const Lane& l : scene_.lanes) {
    if (l.road != 0 || l.kind != Lane::Traffic || l.side >= 0) continue;
    const bool own = l.path == ego.path;
    // The queue runs through the ego's station: its own lane from the ego's bumpers, the others shifted at random.
    const double s0 = own ? ego.s : ego.s + rng.uniform(-6, 6);
    const double half = own ? 0.5 * ego.length : 0.0;
    for (int dir = 1; dir >= -1; dir -= 2) {
      const int n = static_cast<int>(std::round(draw(rng, dir > 0 ? q.ahead : q.behind)));
      double edge = s0 + dir * half;  // the last placed vehicle's bumper facing the next
      for (int k = 0; k < n; ++k) {
        Actor a;
        // Right ahead of the ego: a car, seen from behind.
        if (own && dir > 0 && k == 0) drawCar(a, config_, rng);
        else drawVehicle(a, config_, rng);
        const double gap = draw(rng, q.gap);
        a.s = edge + dir * (gap + 0.5 * a.length);
        edge = a.s + dir * 0.5 * a.length;
        if (a.s < 5 || a.s > l.path->length() - 10) break;
        a.path = l.path;
        a.queued = true;
        a.jam_gap = gap;
        a.v = 0;
        a.v_cruise = a.v_target = draw(rng, q.speed);
        a.next_change = draw(rng, config_.traffic.speed_change_interval);
        findStops(a);
        tryAdd(a);
      }
    }
  }
}

void Traffic::tryAdd(Actor a) {
  place(a);
  if (overlapsAny(a, worldBox(a))) return;
  for (const Actor& o : actors)
    if (boxesOverlap(worldBox(o), worldBox(a), 0.3)) return;
  if (boxesOverlap(worldBox(ego), worldBox(a), 0.5)) return;
  a.track_id = next_id_++;
  actors.push_back(std::move(a));
}

bool Traffic::nearCrossing(const Eigen::Vector2d& p, double d) const {
  const Road& main = scene_.roads[0];
  double lat = 0;
  const double s = main.center.project(p, &lat);
  for (double c : scene_.crossings)
    if (std::abs(c - s) < d && std::abs(lat) < main.half_width + main.sidewalk + 1) return true;
  return false;
}

void Traffic::spawnParked(const Lane& l, const Path& route, double view_range, Rng& rng) {
  const TrafficConfig& tc = config_.traffic;
  const Path& P = *l.path;
  const double len = P.length();
  for (double s = rng.uniform(2, 6); s + 3 < len; s += 6.0) {
    const PathPose pp = P.at(s);
    if (!rng.chance(tc.parked_probability)) continue;
    if (!nearRoute(route, pp.p, view_range + 20) || nearCrossing(pp.p, 7.5) ||
        scene_.onOtherCarriageway(pp.p, l.road, 7.0))
      continue;
    Actor a;
    drawVehicle(a, config_, rng);
    a.path = l.path;
    a.s = s;
    a.moving = false;
    place(a);
    a.yaw += rng.normal(0, 0.02);
    const V2 n(-std::sin(pp.yaw), std::cos(pp.yaw));
    const double shift = rng.normal(0, 0.08);
    a.x += shift * n.x();
    a.y += shift * n.y();
    a.path = nullptr;
    tryAdd(a);
  }
}

void Traffic::spawnCars(const Lane& l, Rng& rng) {
  const TrafficConfig& tc = config_.traffic;
  const double len = l.path->length();
  const int n = static_cast<int>(std::round(tc.car_density * len / 100.0 * rng.uniform(0.8, 1.2)));
  for (int i = 0; i < n; ++i) {
    Actor a;
    drawVehicle(a, config_, rng);
    a.path = l.path;
    a.s = rng.uniform(5, len - 10);
    a.v_cruise = a.v_target = draw(rng, tc.car_speed);
    a.v = a.v_target;
    a.next_change = draw(rng, tc.speed_change_interval);
    // A right turn at the next intersection ahead, for some.
    if (rng.chance(tc.turn_probability)) planRightTurn(a, l);
    findStops(a);
    tryAdd(a);
  }
}

void Traffic::planRightTurn(Actor& a, const Lane& l) const {
  const Path& P = *l.path;
  const double len = P.length();
  for (std::size_t k = 0; k < scene_.intersections.size(); ++k) {
    const Intersection& in = scene_.intersections[k];
    double lat = 0;
    const double sc = P.project(in.center, &lat);
    if (std::abs(lat) > 10 || sc < a.s + 15 || sc > len - 20) continue;
    const double yaw = P.at(sc).yaw;
    // The lane leaving the intersection to our right: heading = our heading - 90 degrees.
    for (const Lane& o : scene_.lanes) {
      if (o.kind != Lane::Traffic || o.index != 0 || (o.road != in.cross_road && o.road != 0) || o.road == l.road) continue;
      double olat = 0;
      const double so = o.path->project(in.center, &olat);
      if (std::abs(olat) > 10) continue;
      const double oyaw = o.path->at(so).yaw;
      if (std::abs(std::remainder(oyaw - (yaw - M_PI / 2), 2 * M_PI)) > 0.3) continue;
      Path route = filletRoute(P, sc, *o.path, so, 7.0);
      if (!route.empty()) a.path = std::make_shared<const Path>(route);
      break;
    }
    break;
  }
}

void Traffic::spawnCyclists(const Lane& l, const Path& route, double view_range, Rng& rng) {
  const TrafficConfig& tc = config_.traffic;
  const Path& P = *l.path;
  const double len = P.length();
  const int n = static_cast<int>(std::round(tc.cyclist_density * len / 100.0 * rng.uniform(0.8, 1.2)));
  for (int i = 0; i < n; ++i) {
    Actor a;
    a.kind = ActorKind::Cyclist;
    a.surfaces = drawSurfaces(config_, rng);
    a.stature = std::clamp(rng.normal(1.76, 0.07), 1.55, 1.95);
    // Builds of bicycle and rider, so that the label boxes spread as KITTI tracking's 36 cyclist tracks do (length /
    // width / height p10-p90 1.59-1.93 / 0.47-0.84 / 1.64-1.85 m): bikes of every size, road to city handlebars,
    // riders from upright to crouched.
    a.length = std::clamp(rng.normal(1.73, 0.13), 1.45, 2.05);
    a.bar_width = std::clamp(rng.normal(0.52, 0.09), 0.38, 0.72);
    a.breadth = std::clamp(rng.normal(0.36, 0.03), 0.30, 0.44) * a.stature / 1.76;
    a.lean = std::clamp(rng.normal(0.6, 0.25), 0.2, 1.05);
    a.phase = rng.uniform(0, 2 * M_PI);
    fitArticulatedBox(a, rng);
    a.mesh = actorMesh(a);
    a.path = l.path;
    a.s = rng.uniform(5, len - 5);
    if (!nearRoute(route, P.at(a.s).p, view_range + 100)) continue;
    a.v_cruise = a.v_target = draw(rng, tc.cyclist_speed);
    a.v = a.v_target;
    a.next_change = draw(rng, tc.speed_change_interval);
    findStops(a);
    tryAdd(a);
  }
}

void Traffic::spawnPedestrians(const Lane& l, const Path& route, double view_range, Rng& rng) {
  const TrafficConfig& tc = config_.traffic;
  const Road& road = scene_.roads[l.road];
  const Path& P = *l.path;
  const double len = P.length();
  const int n = static_cast<int>(std::round(0.5 * tc.pedestrian_density * len / 100.0 * rng.uniform(0.8, 1.2)));
  for (int i = 0; i < n; ++i) {
    Actor a;
    a.kind = ActorKind::Pedestrian;
    a.surfaces = drawSurfaces(config_, rng);
    a.stature = std::clamp(rng.normal(1.72, 0.09), 1.45, 2.0);
    // Shoulder breadth across the arms, clothes included (bideltoid breadth: about 0.50 m in men, 0.43 in women).
    a.breadth = std::clamp(rng.normal(0.48, 0.035), 0.40, 0.58) * a.stature / 1.72;
    // Chest depth (anthropometric surveys: 0.22-0.27 m) with clothes; coats and bags vary it.
    a.depth = std::clamp(rng.normal(0.28, 0.03), 0.22, 0.36) * a.stature / 1.72;
    a.backpack = rng.chance(0.2);
    a.v_cruise = draw(rng, tc.pedestrian_speed);
    a.swing_max = std::clamp(0.22 + 0.12 * a.v_cruise, 0.2, 0.5);
    a.phase = rng.uniform(0, 2 * M_PI);
    a.s = rng.uniform(2, len - 2);
    if (!nearRoute(route, P.at(a.s).p, view_range + 40)) continue;
    const bool standing = rng.chance(tc.pedestrian_standing);
    if (standing) {
      if (road.sidewalk < 4.0) continue;
      // Between the two walkways, facing anywhere.
      const PathPose pp = l.path->at(a.s);
      double lat = 0;
      const PathPose rp = road.center.at(road.center.project(pp.p, &lat));
      const double mid = road.half_width + 0.5 * (1.6 + road.sidewalk - 0.8);
      const V2 n(-std::sin(rp.yaw), std::cos(rp.yaw));
      a.moving = false;
      a.swing_max = 0;
      fitArticulatedBox(a, rng);
      a.mesh = actorMesh(a);
      a.path = std::make_shared<const Path>(std::vector<V2>{rp.p + (lat >= 0 ? mid : -mid) * n,
                                                            rp.p + (lat >= 0 ? mid : -mid) * n + V2(std::cos(rp.yaw), std::sin(rp.yaw))});
      a.s = 0;
      place(a);
      a.yaw = rng.uniform(-M_PI, M_PI);
      a.path = nullptr;
      tryAdd(a);
      continue;
    }
    fitArticulatedBox(a, rng);
    a.v_target = a.v = a.v_cruise;
    a.next_change = draw(rng, tc.speed_change_interval);
    a.path = l.path;
    // Some cross the main road at the next crossing ahead (from the inner walkway to the far inner walkway).
    if (l.road == 0 && l.index == 0 && rng.chance(tc.pedestrian_crossing)) planCrossing(a, l);
    a.mesh = actorMesh(a);
    tryAdd(a);
  }
}

void Traffic::planCrossing(Actor& a, const Lane& l) const {
  const Road& main = scene_.roads[0];
  const Path& P = *l.path;
  for (double c : scene_.crossings) {
    const V2 cp = main.center.at(c).p;
    double lat = 0;
    const double sc = P.project(cp, &lat);
    if (sc < a.s + 2 || sc > a.s + 60) continue;
    const Lane* far = nullptr;
    for (const Lane& o : scene_.lanes)
      if (o.road == 0 && o.kind == Lane::Walk && o.index == 0 && o.side == -l.side) far = &o;
    if (!far) break;
    const double sf = far->path->project(cp);
    Path route = P.slice(0, sc, 1.0);
    const V2 a0 = P.at(sc).p, a1 = far->path->at(sf).p;
    std::vector<V2> across;
    const int steps = static_cast<int>(std::ceil((a1 - a0).norm()));
    for (int k = 1; k <= steps; ++k) across.push_back(a0 + (a1 - a0) * (static_cast<double>(k) / steps));
    route.append(Path(across));
    route.append(far->path->slice(sf, far->path->length(), 1.0));
    a.path = std::make_shared<const Path>(route);
    break;
  }
}

}  // namespace sim
}  // namespace ret3d
