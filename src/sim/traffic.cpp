#include <algorithm>
#include <cmath>

#include "actor_internal.h"
#include "ret3d/core/geometry.h"
#include "ret3d/sim/actors.h"

namespace ret3d {
namespace sim {

namespace {

using V2 = Eigen::Vector2d;
using detail::boxesOverlap;
using detail::draw;

// IDM parameters per kind: maximum acceleration, comfortable deceleration, jam distance, time headway.
struct Idm {
  double a, b, s0, T;
};
Idm idmOf(ActorKind k) {
  switch (k) {
    case ActorKind::Pedestrian: return {1.0, 2.0, 0.6, 0.6};
    case ActorKind::Cyclist: return {1.0, 2.5, 1.5, 1.0};
    default: return {1.5, 3.0, 2.0, 1.2};
  }
}

// Lateral margin of an actor's corridor when looking for what is ahead.
// Beyond this distance from the ego, actors do not move (nothing sees them).
constexpr double kActiveRadius = 260.0;

double corridorMargin(ActorKind k) { return k == ActorKind::Pedestrian ? 0.15 : 0.25; }

// Gait (a stride of 0.8 x stature per cycle) or crank (5.3 m per turn in a middle gear) advance over a step.
void advancePhase(Actor& a, double v, double dt) {
  if (a.kind == ActorKind::Pedestrian) a.phase += 2 * M_PI * v * dt / (0.8 * a.stature);
  if (a.kind == ActorKind::Cyclist) a.phase += 2 * M_PI * v * dt / 5.3;
}

}  // namespace

// ---- traffic ----------------------------------------------------------------------------------------------------

Traffic::Traffic(const SimConfig& config, const Scene& scene) : config_(config), scene_(scene) {}

Eigen::Isometry3d Traffic::egoPose() const { return ego_pose_; }

void Traffic::place(Actor& a) {
  if (!a.path) return;
  const PathPose pp = a.path->at(a.s);
  a.x = pp.p.x();
  a.y = pp.p.y();
  a.yaw = pp.yaw;
  a.vx = a.v * std::cos(a.yaw);
  a.vy = a.v * std::sin(a.yaw);
  double z = scene_.baseHeight(pp.p);
  if (a.kind == ActorKind::Pedestrian) {
    int road = 0;
    const double d = scene_.roadDistance(pp.p, &road);
    if (d > 0 && d < scene_.roads[road].sidewalk) z += config_.road.curb_height;
  }
  a.z = z;
}

void Traffic::findStops(Actor& a) const {
  a.stops.clear();
  if (!a.path || config_.traffic.traffic_light_cycle <= 0) return;
  for (std::size_t i = 0; i < scene_.intersections.size(); ++i) {
    const Intersection& in = scene_.intersections[i];
    double lat = 0;
    const double sc = a.path->project(in.center, &lat);
    if (std::abs(lat) > 7.0 || sc < 1.0 || sc > a.path->length() - 1.0) continue;
    const double yaw_main = scene_.roads[0].center.at(in.s_main).yaw;
    const double yaw_in = a.path->at(std::max(0.0, sc - 15)).yaw;
    const bool main_approach = std::abs(std::cos(yaw_in - yaw_main)) > 0.7;
    const double other_half = main_approach ? scene_.roads[in.cross_road].half_width : scene_.roads[0].half_width;
    a.stops.push_back({sc - other_half - 4.0, static_cast<int>(i), main_approach});
  }
}

bool Traffic::green(int intersection, bool main_approach, double t) const {
  const double cycle = config_.traffic.traffic_light_cycle;
  if (cycle <= 0) return true;
  const double ph = std::fmod(t + scene_.intersections[intersection].light_phase, cycle);
  // Main road green for the first 55 % of the cycle, cross road for the rest less an all-red 5 %.
  return main_approach ? ph < 0.55 * cycle : (ph >= 0.6 * cycle);
}

namespace {
long long cellKey(long ix, long iy) {
  return static_cast<long long>((static_cast<unsigned long long>(ix) << 32) ^ static_cast<unsigned long long>(iy & 0xffffffff));
}
}  // namespace

void Traffic::buildGrid() {
  grid_.clear();
  auto add = [&](const Actor& a, int i) {
    grid_[cellKey(static_cast<long>(std::floor(a.x / kCell)), static_cast<long>(std::floor(a.y / kCell)))].push_back(i);
  };
  add(ego, -1);
  for (std::size_t i = 0; i < actors.size(); ++i)
    if (actors[i].active) add(actors[i], static_cast<int>(i));
}

std::vector<int> Traffic::near(double x, double y, double radius) const {
  // Positions are those at the grid's build time; callers add the distance actors move in a sub-step to `radius`.
  std::vector<int> out;
  const long x0 = static_cast<long>(std::floor((x - radius) / kCell)), x1 = static_cast<long>(std::floor((x + radius) / kCell));
  const long y0 = static_cast<long>(std::floor((y - radius) / kCell)), y1 = static_cast<long>(std::floor((y + radius) / kCell));
  for (long ix = x0; ix <= x1; ++ix)
    for (long iy = y0; iy <= y1; ++iy) {
      auto it = grid_.find(cellKey(ix, iy));
      if (it != grid_.end()) out.insert(out.end(), it->second.begin(), it->second.end());
    }
  std::sort(out.begin(), out.end());  // a fixed order, whatever the hash map's
  return out;
}

bool Traffic::overlapsAny(const Actor& a, const Box& b) const {
  const double inflate = 0.05;
  if (&a != &ego && !replay_ && boxesOverlap(worldBox(ego), b, inflate)) return true;
  for (int i : near(b.x, b.y, 12.0)) {
    if (i < 0) continue;
    const Actor& o = actors[i];
    if (&o == &a || !o.active) continue;
    if (boxesOverlap(worldBox(o), b, inflate)) return true;
  }
  return false;
}

double Traffic::leaderGap(const Actor& a, double horizon, double* leader_speed) const {
  double best = 1e9;
  *leader_speed = 0;
  const Path& P = *a.path;
  const double half = 0.5 * a.width + corridorMargin(a.kind);
  auto consider = [&](const Actor& o) {
    if (&o == &a || !o.active) return;
    const double dx = o.x - a.x, dy = o.y - a.y;
    if (dx * dx + dy * dy > (horizon + 8) * (horizon + 8)) return;
    // Roughly ahead of us (paths bend little over a horizon).
    if (dx * std::cos(a.yaw) + dy * std::sin(a.yaw) < -a.length) return;
    const Box ob = worldBox(o);
    // Nearest vertex of our path ahead (vertices are about 1 m apart).
    const auto& st = P.stations();
    const auto& pts = P.points();
    std::size_t i0 = static_cast<std::size_t>(std::lower_bound(st.begin(), st.end(), a.s - 0.5 * a.length) - st.begin());
    double best_d = 1e18, sb = a.s;
    for (std::size_t k = i0; k < pts.size() && st[k] <= a.s + horizon; ++k) {
      const double d = (pts[k] - V2(ob.x, ob.y)).squaredNorm();
      if (d < best_d) {
        best_d = d;
        sb = st[k];
      }
    }
    if (best_d > (horizon + 8) * (horizon + 8)) return;
    const PathPose pp = P.at(sb);
    const V2 t(std::cos(pp.yaw), std::sin(pp.yaw)), n(-t.y(), t.x());
    double lat_lo = 1e9, lat_hi = -1e9, lon_lo = 1e9;
    for (const auto& c : bevCorners(ob)) {
      const V2 r = c - pp.p;
      lat_lo = std::min(lat_lo, r.dot(n));
      lat_hi = std::max(lat_hi, r.dot(n));
      lon_lo = std::min(lon_lo, r.dot(t));
    }
    if (lat_hi < -half || lat_lo > half) return;
    const double gap = sb + lon_lo - (a.s + 0.5 * a.length);
    if (gap < -0.5 * a.length) return;  // beside or behind us
    if (gap < best) {
      best = std::max(gap, 0.01);
      *leader_speed = std::max(0.0, o.vx * t.x() + o.vy * t.y());
    }
  };
  if (&a != &ego) consider(ego);
  for (int i : near(a.x, a.y, horizon + 12.0))
    if (i >= 0) consider(actors[i]);
  return best;
}

void Traffic::advance(Actor& a, double t, double dt, Rng& rng) {
  if (!a.active || !a.moving || !a.path) return;
  const TrafficConfig& tc = config_.traffic;
  const Range speeds = a.queued ? tc.queue.speed
                       : &a == &ego ? tc.ego_speed
                       : a.kind == ActorKind::Pedestrian ? tc.pedestrian_speed
                       : a.kind == ActorKind::Cyclist ? tc.cyclist_speed : tc.car_speed;
  const double stop_probability = a.queued ? tc.queue.stop_probability : tc.stop_probability;
  if (a.queued && &a == &ego) {
    // The queued ego only follows: it stops and goes with the vehicle ahead.
    a.v_target = speeds.hi + 0.5;
  } else if (t >= a.next_change) {
    // New target speed now and then; sometimes a stop (vehicles only; pedestrians just vary their pace).
    a.next_change = t + draw(rng, tc.speed_change_interval);
    if (a.kind != ActorKind::Pedestrian && rng.chance(stop_probability)) {
      a.v_target = 0;
      a.stop_until = t + rng.uniform(2, 6);
    } else {
      a.v_target = a.kind == ActorKind::Pedestrian ? std::clamp(a.v_cruise * rng.uniform(0.85, 1.15), speeds.lo, speeds.hi)
                                                   : draw(rng, speeds);
    }
  }
  if (a.v_target == 0 && a.stop_until >= 0 && t >= a.stop_until) {
    a.v_target = std::max(draw(rng, speeds), 0.5 * speeds.hi);
    a.stop_until = -1;
  }
  Idm p = idmOf(a.kind);
  if (a.queued) p.T = tc.queue.headway;
  if (a.jam_gap >= 0) p.s0 = a.jam_gap;
  const double horizon = a.kind == ActorKind::Pedestrian ? 6.0 : std::max(15.0, a.v * 4 + 10);
  double vl = 0;
  double gap = leaderGap(a, horizon, &vl);
  // Red light: a standing obstacle at the stop line, unless too close to stop comfortably (then go).
  const double front = a.s + 0.5 * a.length;
  for (const Actor::Stop& st : a.stops) {
    const double g = st.s - front;
    if (g < -0.5 || g > 80) continue;
    if (!green(st.intersection, st.main_approach, t) && g > a.v * a.v / (2 * p.b) * 0.7 - 0.5 && g < gap) {
      gap = std::max(g, 0.01);
      vl = 0;
    }
  }
  double acc;
  if (a.v_target <= 0.01) {
    acc = -p.b;
  } else {
    const double s_star = p.s0 + std::max(0.0, a.v * p.T + a.v * (a.v - vl) / (2 * std::sqrt(p.a * p.b)));
    acc = p.a * (1 - std::pow(a.v / a.v_target, 4) - (s_star / gap) * (s_star / gap));
  }
  acc = std::max(acc, -9.0);
  double v = std::max(0.0, a.v + acc * dt);
  const double s_new = a.s + v * dt;
  if (s_new >= a.path->length() - 0.5 * a.length) {
    if (&a == &ego) {
      v = 0;
    } else {
      a.active = false;  // left the map
      return;
    }
  }
  // Propose the move in place; undo it when it would overlap anything.
  const double old_s = a.s, old_x = a.x, old_y = a.y, old_z = a.z, old_yaw = a.yaw;
  a.s = std::min(s_new, a.path->length());
  a.v = v;
  place(a);
  if (v > 0 && overlapsAny(a, worldBox(a))) {
    a.s = old_s;
    a.x = old_x;
    a.y = old_y;
    a.z = old_z;
    a.yaw = old_yaw;
    a.v = 0;
    a.vx = a.vy = 0;
    return;
  }
  advancePhase(a, v, dt);
}

void Traffic::step(double t, double dt, int frame, Rng& rng) {
  if (replay_) {
    const std::size_t f = static_cast<std::size_t>(std::max(0, frame));
    ego_pose_ = ego_poses_[std::min(f, ego_poses_.size() - 1)];
    for (Actor& a : actors) {
      const bool has = f < a.replay.size() && a.replay[f].has_value();
      a.active = has;
      if (!has) continue;
      const Box& b = *a.replay[f];
      a.length = b.length;
      a.width = b.width;
      a.height = b.height;
      const double c = std::cos(b.yaw), s = std::sin(b.yaw);
      a.yaw = b.yaw;
      a.x = b.x - (c * a.box_offset.x() - s * a.box_offset.y());
      a.y = b.y - (s * a.box_offset.x() + c * a.box_offset.y());
      a.z = b.z - 0.5 * b.height;
      // Velocity from neighbouring frames.
      const std::optional<Box>* prev = f > 0 && a.replay[f - 1] ? &a.replay[f - 1] : nullptr;
      const std::optional<Box>* next = f + 1 < a.replay.size() && a.replay[f + 1] ? &a.replay[f + 1] : nullptr;
      a.vx = a.vy = 0;
      if (prev || next) {
        const Box& p0 = prev ? **prev : b;
        const Box& p1 = next ? **next : b;
        const double span = ((prev ? 1 : 0) + (next ? 1 : 0)) * dt;
        a.vx = (p1.x - p0.x) / span;
        a.vy = (p1.y - p0.y) / span;
      }
      a.v = std::hypot(a.vx, a.vy);
      advancePhase(a, a.v, dt);
      if (a.articulated()) a.mesh = actorMesh(a);
    }
    return;
  }
  // Two sub-steps per frame keep the car-following stable at 10 Hz.
  // Actors far from the ego (beyond any sensor's view) wait where they are, which keeps long roads cheap.
  const int sub = 2;
  for (int k = 0; k < sub; ++k) {
    const double tk = t + k * dt / sub;
    buildGrid();
    advance(ego, tk, dt / sub, rng);
    for (Actor& a : actors)
      if (std::hypot(a.x - ego.x, a.y - ego.y) < kActiveRadius) advance(a, tk, dt / sub, rng);
  }
  for (Actor& a : actors)
    if (a.active && a.articulated()) a.mesh = actorMesh(a);
  ego_pose_ = Eigen::Isometry3d::Identity();
  ego_pose_.translation() = Eigen::Vector3d(ego.x, ego.y, ego.z);
  ego_pose_.linear() = Eigen::AngleAxisd(ego.yaw, Eigen::Vector3d::UnitZ()).toRotationMatrix();
}

void Traffic::setReplay(std::vector<Actor> replayed, std::vector<Eigen::Isometry3d> ego_poses) {
  replay_ = true;
  actors = std::move(replayed);
  ego_poses_ = std::move(ego_poses);
  ego_pose_ = ego_poses_.empty() ? Eigen::Isometry3d::Identity() : ego_poses_[0];
  for (Actor& a : actors) {
    a.moving = false;
    next_id_ = std::max(next_id_, a.track_id + 1);
  }
}

}  // namespace sim
}  // namespace ret3d
