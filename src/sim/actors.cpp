#include "ret3d/sim/actors.h"

#include <algorithm>
#include <cmath>

#include "actor_internal.h"
#include "ret3d/core/geometry.h"

namespace ret3d {
namespace sim {

namespace {

PersonShape personShape(const Actor& a) { return {a.stature, a.breadth, a.depth, a.backpack}; }
RiderShape riderShape(const Actor& a) { return {a.length, a.stature, a.bar_width, a.breadth, a.lean}; }

using V2 = Eigen::Vector2d;
using detail::draw;

}  // namespace

namespace detail {

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

}  // namespace detail

using detail::drawSurfaces;

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

}  // namespace sim
}  // namespace ret3d
