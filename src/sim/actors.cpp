#include "ret3d/sim/actors.h"

#include <algorithm>
#include <cmath>

#include "ret3d/core/geometry.h"

namespace ret3d {
namespace sim {

namespace {

PersonShape personShape(const Actor& a) { return {a.stature, a.breadth, a.depth, a.backpack}; }
RiderShape riderShape(const Actor& a) { return {a.length, a.stature, a.bar_width, a.breadth, a.lean}; }

using V2 = Eigen::Vector2d;

double draw(Rng& rng, const Range& r) { return rng.uniform(r.lo, r.hi); }

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

ActorSurfaces drawSurfaces(const SimConfig& c, Rng& rng) {
  ActorSurfaces s;
  s.paint = drawSurface(c, "paint", rng);
  s.glass = drawSurface(c, "car_glass", rng);
  s.tire = drawSurface(c, "tire", rng);
  s.plate = drawSurface(c, "plate", rng);
  s.skin = drawSurface(c, "skin", rng);
  s.clothing = drawSurface(c, "clothing", rng);
  s.clothing2 = drawSurface(c, "clothing", rng);
  s.metal = drawSurface(c, "metal", rng);
  return s;
}

// Box of a pedestrian or cyclist: the bounds of its mesh over a whole gait (or crank) cycle, plus the label margin,
// so one size per track (as a labeller draws it) holds every frame's mesh; a cyclist's width then as KITTI's labellers
// draw it (below). A pedestrian's box is then drawn as KITTI's
// labellers draw theirs: looser than the body, one size per track, from the sizes of KITTI tracking's 165 pedestrian
// tracks (width 0.68 +- 0.15 m, length 0.82 +- 0.23 m), never tighter than the mesh. Without it the boxes hugged the
// shoulders (median width 0.53 m against KITTI's 0.73 per box), and a detector taught on them drew real pedestrians'
// boxes too thin for IoU 0.5.
void fitArticulatedBox(Actor& a, Rng& rng) {
  Eigen::AlignedBox3f b;
  for (int k = 0; k < 16; ++k) {
    const double ph = 2 * M_PI * k / 16;
    TriangleMesh m = a.kind == ActorKind::Pedestrian ? pedestrianMesh(personShape(a), ph, a.swing_max, a.surfaces)
                                                     : cyclistMesh(riderShape(a), ph, a.surfaces);
    b.extend(m.bounds());
    if (a.kind == ActorKind::Pedestrian) b.extend(pedestrianMesh(personShape(a), ph, 0.5 * a.swing_max, a.surfaces).bounds());
  }
  if (a.kind == ActorKind::Pedestrian) b.extend(pedestrianMesh(personShape(a), 0, 0, a.surfaces).bounds());
  const double m = kLabelMargin;
  a.length = b.sizes().x() + 2 * m;
  a.width = b.sizes().y() + 2 * m;
  a.height = b.max().z() + m;
  a.box_offset = V2(b.center().x(), b.center().y());
  if (a.kind == ActorKind::Pedestrian) {
    a.length = std::max(a.length, std::clamp(rng.normal(0.82, 0.2), 0.45, 1.2));
    a.width = std::max(a.width, std::clamp(rng.normal(0.68, 0.15), 0.45, 1.0));
  } else {
    // KITTI's labellers draw a cyclist's width looser or tighter than its elbows and handlebars (p10 0.47 m, narrower
    // than any rider's arms on the bars): drawn here as they draw it, half from the build, half from their spread.
    a.width = std::clamp(0.5 * a.width + 0.5 * rng.normal(0.60, 0.28), 0.42, 0.95);
  }
}

bool boxesOverlap(const Box& a, const Box& b, double inflate) {
  const double r = 0.5 * (std::hypot(a.length, a.width) + std::hypot(b.length, b.width)) + inflate;
  if (std::abs(a.x - b.x) > r || std::abs(a.y - b.y) > r) return false;
  Box ai = a;
  ai.length += 2 * inflate;
  ai.width += 2 * inflate;
  return bevIntersectionArea(ai, b) > 1e-9;
}

}  // namespace

ObjectClass Actor::objectClass() const {
  switch (kind) {
    case ActorKind::Car: return ObjectClass::Car;
    case ActorKind::Pedestrian: return ObjectClass::Pedestrian;
    case ActorKind::Cyclist: return ObjectClass::Cyclist;
    case ActorKind::Obstacle: break;
  }
  return ObjectClass::Unknown;
}

Box worldBox(const Actor& a) {
  Box b;
  const double c = std::cos(a.yaw), s = std::sin(a.yaw);
  b.x = a.x + c * a.box_offset.x() - s * a.box_offset.y();
  b.y = a.y + s * a.box_offset.x() + c * a.box_offset.y();
  b.z = a.z + 0.5 * a.height;
  b.length = a.length;
  b.width = a.width;
  b.height = a.height;
  b.yaw = wrapAngle(a.yaw);
  b.vx = a.vx;
  b.vy = a.vy;
  b.label = a.objectClass();
  b.track_id = a.track_id;
  return b;
}

Eigen::Isometry3d actorPose(const Actor& a) {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.translation() = Eigen::Vector3d(a.x, a.y, a.z);
  T.linear() = Eigen::AngleAxisd(a.yaw, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  return T;
}

// Gait (a stride of 0.8 x stature per cycle) or crank (5.3 m per turn in a middle gear) advance over a step.
static void advancePhase(Actor& a, double v, double dt) {
  if (a.kind == ActorKind::Pedestrian) a.phase += 2 * M_PI * v * dt / (0.8 * a.stature);
  if (a.kind == ActorKind::Cyclist) a.phase += 2 * M_PI * v * dt / 5.3;
}

int Actor::variant() const {
  if (!articulated()) return 0;
  if (kind == ActorKind::Pedestrian && (!moving || v < 0.05)) return kPhaseSteps;
  const double step = 2 * M_PI / kPhaseSteps;
  const long k = std::lround(phase / step);
  return static_cast<int>(((k % kPhaseSteps) + kPhaseSteps) % kPhaseSteps);
}

TriangleMesh actorMesh(const Actor& a) {
  const int var = a.variant();
  const double phase = 2 * M_PI * var / kPhaseSteps;
  switch (a.kind) {
    case ActorKind::Pedestrian:
      return pedestrianMesh(personShape(a), phase, var == kPhaseSteps ? 0.0 : a.swing_max, a.surfaces);
    case ActorKind::Cyclist: return cyclistMesh(riderShape(a), phase, a.surfaces);
    default: return carMesh(a.body, a.length, a.width, a.height, a.surfaces);
  }
}

void drawCar(Actor& a, const SimConfig& config, Rng& rng) {
  const TrafficConfig& t = config.traffic;
  // Means chosen so the mix (0.4 / 0.25 / 0.25 / 0.1) averages KITTI's Car size, 3.9 x 1.6 x 1.56 m.
  struct Dist {
    CarBody body;
    double weight, l, w, h;
  };
  const Dist d[4] = {{CarBody::Sedan, t.sedan, 3.95, 1.62, 1.45},
                     {CarBody::Hatchback, t.hatchback, 3.50, 1.58, 1.50},
                     {CarBody::Suv, t.suv, 4.20, 1.72, 1.66},
                     {CarBody::Van, t.van, 4.50, 1.76, 1.85}};
  const double total = t.sedan + t.hatchback + t.suv + t.van;
  double u = rng.uniform(0, total);
  int k = 0;
  while (k < 3 && u >= d[k].weight) u -= d[k++].weight;
  a.kind = ActorKind::Car;
  a.body = d[k].body;
  a.length = std::clamp(rng.normal(d[k].l, 0.2), 3.0, 5.2);
  a.width = std::clamp(rng.normal(d[k].w, 0.05), 1.45, 1.95);
  a.height = std::clamp(rng.normal(d[k].h, 0.05), 1.3, 2.0);
  a.box_offset = V2::Zero();
  a.surfaces = drawSurfaces(config, rng);
  if (!config.paint.empty()) a.surfaces.paint.reflectivity = static_cast<float>(drawPaint(config, rng));
  a.mesh = actorMesh(a);
}

double drawPaint(const SimConfig& config, Rng& rng) {
  if (config.paint.empty()) return drawSurface(config, "paint", rng).reflectivity;
  double total = 0;
  for (const PaintMode& m : config.paint) total += m.weight;
  double u = rng.uniform(0, total);
  std::size_t k = 0;
  while (k + 1 < config.paint.size() && u >= config.paint[k].weight) u -= config.paint[k++].weight;
  return std::max(0.005, draw(rng, config.paint[k].reflectivity));
}

void drawVehicle(Actor& a, const SimConfig& config, Rng& rng) {
  const TrafficConfig& t = config.traffic;
  const double u = t.truck + t.delivery_van > 0 ? rng.uniform() : 1.0;
  if (u >= t.truck + t.delivery_van) {
    drawCar(a, config, rng);
    return;
  }
  // KITTI's Truck (box trucks: 10.1 x 2.6 x 3.3 m on average in KITTI object; city box trucks shorter) and Van (5.1 x
  // 1.9 x 2.2 m), labelled with their own type, which KITTI-style training ignores for Car.
  const bool truck = u < t.truck;
  a.kind = ActorKind::Obstacle;
  a.kitti_type = truck ? "Truck" : "Van";
  a.body = truck ? CarBody::Truck : CarBody::Van;
  a.length = truck ? std::clamp(rng.normal(8.0, 1.5), 6.0, 11.5) : std::clamp(rng.normal(5.1, 0.35), 4.4, 6.2);
  a.width = truck ? std::clamp(rng.normal(2.45, 0.08), 2.25, 2.6) : std::clamp(rng.normal(1.95, 0.07), 1.8, 2.15);
  a.height = truck ? std::clamp(rng.normal(3.2, 0.25), 2.7, 3.8) : std::clamp(rng.normal(2.3, 0.15), 1.95, 2.8);
  a.box_offset = V2::Zero();
  a.surfaces = drawSurfaces(config, rng);
  a.surfaces.paint.reflectivity = static_cast<float>(drawPaint(config, rng));
  a.mesh = actorMesh(a);
}

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
