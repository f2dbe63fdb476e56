#include "ret3d/sim/ground_truth.h"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <thread>

#include "ret3d/core/geometry.h"
#include "ret3d/core/transform.h"

namespace ret3d {
namespace sim {

int occlusionLevel(double visible) { return visible >= 0.8 ? 0 : (visible >= 0.4 ? 1 : 2); }


namespace {

// The camera (image 2) centre and pixel rays in the LiDAR frame: X_rect = K (X + t) for P2 = K [I | t].
struct CameraRays {
  Eigen::Matrix3d Kinv;
  Eigen::Vector3d cam_rect, cam_lidar, cam_world;
  CameraRays(const kitti::Calibration& calib, const Eigen::Isometry3d& T_world_lidar) {
    const Eigen::Matrix3d K = calib.P2.leftCols<3>();
    Kinv = K.inverse();
    const Eigen::Vector3d t2 = Kinv * calib.P2.col(3);
    cam_rect = -t2;
    cam_lidar = calib.rectToVelo(cam_rect);
    cam_world = T_world_lidar * cam_lidar;
  }
};

// Rays (hits) and returns per actor, in one pass over the sweep.
void countActorRays(const Sweep& sweep, std::size_t num_actors, std::vector<std::uint32_t>* hits,
                    std::vector<std::vector<std::size_t>>* returns) {
  hits->assign(num_actors, 0);
  returns->assign(num_actors, {});
  for (std::size_t slot = 0; slot < sweep.size(); ++slot) {
    const int a = sweep.actor[slot];
    if (a < 0 || static_cast<std::size_t>(a) >= num_actors) continue;
    ++(*hits)[a];
    if (sweep.returned[slot]) (*returns)[a].push_back(slot);
  }
}

// The labelled actors within label_range holding at least min_points returns, with their boxes in the LiDAR frame.
std::vector<ObjectTruth> labelledObjects(const std::vector<Actor>& actors, const Sweep& sweep,
                                         const Eigen::Isometry3d& T_lidar_world, const TruthOptions& opt) {
  std::vector<std::uint32_t> hits;
  std::vector<std::vector<std::size_t>> returns;
  countActorRays(sweep, actors.size(), &hits, &returns);
  std::vector<ObjectTruth> out;
  for (std::size_t i = 0; i < actors.size(); ++i) {
    const Actor& a = actors[i];
    if (!a.active || !a.labelled || (a.objectClass() == ObjectClass::Unknown && a.kitti_type.empty())) continue;
    ObjectTruth o;
    o.actor = i;
    o.box = transformBox(worldBox(a), T_lidar_world);
    const double dist = std::hypot(o.box.x, o.box.y);
    if (dist > opt.label_range) continue;
    std::uint32_t inside = 0;
    for (std::size_t slot : returns[i]) {
      const Point& p = sweep.points[slot];
      if (pointInBox(o.box, Eigen::Vector3d(p.x, p.y, p.z))) ++inside;
    }
    o.box.num_points = inside;
    if (static_cast<int>(inside) < opt.min_points) continue;
    o.hits = hits[i];
    out.push_back(std::move(o));
  }
  return out;
}

// Nearest and farthest horizontal distance from the sensor to a box's footprint (for its elevation extremes).
void footprintRange(const Box& box, double* rmin, double* rmax) {
  *rmin = 1e9;
  *rmax = 0;
  for (const auto& c : bevCorners(box)) *rmax = std::max(*rmax, c.norm());
  if (pointInBox(box, Eigen::Vector3d(0, 0, box.z))) *rmin = 0.1;
  const auto bc = bevCorners(box);
  for (int k = 0; k < 4; ++k) {
    const Eigen::Vector2d p = bc[k], q = bc[(k + 1) % 4], d = q - p;
    const double t = std::clamp(-p.dot(d) / d.squaredNorm(), 0.0, 1.0);
    *rmin = std::min(*rmin, (p + t * d).norm());
  }
}

// Unoccluded rays: every slot whose ray passes the box's angular window, cast against the actor alone; sets
// unoccluded and visible_fraction.
void lidarVisibility(ObjectTruth& o, const RayCaster& caster, const Sweep& sweep, const Eigen::Isometry3d& T_world_lidar,
                     const Eigen::Vector3d& ego_velocity, double yaw_rate) {
  const SensorModel& sensor = caster.sensor();
  const int beams = sweep.beams, cols = sweep.columns;
  const auto corners = boxCorners(o.box);
  const double az0 = std::atan2(o.box.y, o.box.x);
  double lo = 0, hi = 0;
  for (const auto& c : corners) {
    const double d = std::remainder(std::atan2(c.y(), c.x()) - az0, 2 * M_PI);
    lo = std::min(lo, d);
    hi = std::max(hi, d);
  }
  double rmin = 0, rmax = 0;
  footprintRange(o.box, &rmin, &rmax);
  const double ztop = o.box.top(), zbot = o.box.bottom();
  const double el_hi = std::atan2(ztop, ztop > 0 ? rmin : rmax) * 180 / M_PI;
  const double el_lo = std::atan2(zbot, zbot < 0 ? rmin : rmax) * 180 / M_PI;
  const double dcol = 2 * M_PI / cols;
  // Column c has azimuth pi - (c + 0.5) dcol; a few columns of slack for motion distortion.
  const int slack = sensor.motion_distortion ? 6 : 1;
  const int c_first = static_cast<int>(std::floor((M_PI - (az0 + hi)) / dcol - 0.5)) - slack;
  const int c_last = static_cast<int>(std::ceil((M_PI - (az0 + lo)) / dcol - 0.5)) + slack;
  std::uint32_t un = 0;
  for (int b = 0; b < beams; ++b) {
    const double el = sensor.elevation_deg[b];
    if (el < el_lo - 0.5 || el > el_hi + 0.5) continue;
    for (int cc = c_first; cc <= c_last; ++cc) {
      const int c = ((cc % cols) + cols) % cols;
      Eigen::Vector3d org, dir;
      caster.slotRay(T_world_lidar, c, b, ego_velocity, yaw_rate, &org, &dir);
      if (caster.intersectActorOnly(o.actor, org, dir, sensor.min_range, sensor.max_range)) ++un;
    }
  }
  o.unoccluded = std::max(un, o.hits);
  o.visible_fraction = o.unoccluded > 0 ? static_cast<double>(o.hits) / o.unoccluded : 0.0;
}

// The image rectangle the actor's mesh projects to (clamped to the image), and how many of its vertices project
// inside the image out of how many.
struct MeshProjection {
  double u0 = 1e18, v0 = 1e18, u1 = -1e18, v1 = -1e18;
  std::size_t total = 0, in_image = 0;
};

MeshProjection projectMesh(const Actor& a, const Eigen::Isometry3d& T_lidar_actor, const kitti::Calibration& calib,
                           const Eigen::Vector2d& image_size) {
  MeshProjection m;
  for (const auto& v : a.mesh.vertices) {
    ++m.total;
    const Eigen::Vector3d r = calib.veloToRect(T_lidar_actor * v.cast<double>());
    if (r.z() < 0.1) continue;
    const auto px = calib.projectRect(r);
    if (!px) continue;
    const bool inside_img = px->x() >= 0 && px->y() >= 0 && px->x() <= image_size.x() - 1 &&
                            px->y() <= image_size.y() - 1;
    if (inside_img) ++m.in_image;
    m.u0 = std::min(m.u0, px->x());
    m.v0 = std::min(m.v0, px->y());
    m.u1 = std::max(m.u1, px->x());
    m.v1 = std::max(m.v1, px->y());
  }
  m.u0 = std::clamp(m.u0, 0.0, image_size.x() - 1);
  m.u1 = std::clamp(m.u1, 0.0, image_size.x() - 1);
  m.v0 = std::clamp(m.v0, 0.0, image_size.y() - 1);
  m.v1 = std::clamp(m.v1, 0.0, image_size.y() - 1);
  return m;
}

// Of camera_samples x camera_samples pixel rays through the rectangle that meet the actor, the share that meets it
// first (nothing else in front).
double cameraVisibleShare(const ObjectTruth& o, const MeshProjection& m, const RayCaster& caster,
                          const CameraRays& cam, const kitti::Calibration& calib,
                          const Eigen::Isometry3d& T_world_lidar, int n) {
  const std::size_t i = o.actor;
  int own = 0, seen = 0;
  for (int iu = 0; iu < n; ++iu) {
    for (int iv = 0; iv < n; ++iv) {
      const double u = m.u0 + (m.u1 - m.u0) * (iu + 0.5) / n, v = m.v0 + (m.v1 - m.v0) * (iv + 0.5) / n;
      const Eigen::Vector3d p_lidar = calib.rectToVelo(cam.cam_rect + cam.Kinv * Eigen::Vector3d(u, v, 1));
      const Eigen::Vector3d dir = (T_world_lidar.linear() * (p_lidar - cam.cam_lidar)).normalized();
      if (!caster.intersectActorOnly(i, cam.cam_world, dir, 0.1, 200.0)) continue;
      ++own;
      double t = 0;
      int hit = -1;
      if (caster.intersect(cam.cam_world, dir, 0.1, 200.0, &t, &hit) && hit == static_cast<int>(i)) ++seen;
    }
  }
  return own > 0 ? static_cast<double>(seen) / own : 0.0;
}

// Camera: the KITTI label, where the mesh projects, how much is outside the image, how much is hidden behind other
// things.
void cameraLabel(ObjectTruth& o, const Actor& a, const RayCaster& caster, const CameraRays& cam,
                 const kitti::Calibration& calib, const Eigen::Isometry3d& T_world_lidar,
                 const Eigen::Isometry3d& T_lidar_world, const TruthOptions& opt, int frame) {
  o.label = kitti::boxToLabel(o.box, calib, opt.image_size);
  if (!a.kitti_type.empty()) o.label.type = a.kitti_type;
  o.label.frame = frame;
  o.label.score.reset();  // ground truth, not a detection
  const MeshProjection m = projectMesh(a, T_lidar_world * actorPose(a), calib, opt.image_size);
  o.camera_truncation = m.total > 0 ? 1.0 - static_cast<double>(m.in_image) / m.total : 1.0;
  if (m.in_image == 0 || m.u1 - m.u0 < 1 || m.v1 - m.v0 < 1) {
    o.label.bbox = {0, 0, 0, 0};
    o.label.truncated = 2;
    o.label.occluded = 3;
    o.camera_truncation = 1.0;
    o.camera_visible = 0;
    return;
  }
  o.label.bbox = {m.u0, m.v0, m.u1, m.v1};
  // Tracking-layout truncation levels: 0 in the image, 1 partly outside, 2 (almost) all outside.
  o.label.truncated = o.camera_truncation < 0.1 ? 0 : (o.camera_truncation < 0.9 ? 1 : 2);
  o.camera_visible = cameraVisibleShare(o, m, caster, cam, calib, T_world_lidar, opt.camera_samples);
  o.label.occluded = occlusionLevel(o.camera_visible);
}

}  // namespace

std::vector<ObjectTruth> labelFrame(const std::vector<Actor>& actors, const RayCaster& caster, const Sweep& sweep,
                                    const Eigen::Isometry3d& T_world_lidar, const kitti::Calibration& calib,
                                    const TruthOptions& opt, int frame, const Eigen::Vector3d& ego_velocity,
                                    double yaw_rate) {
  const Eigen::Isometry3d T_lidar_world = T_world_lidar.inverse();
  const CameraRays cam(calib, T_world_lidar);
  std::vector<ObjectTruth> out = labelledObjects(actors, sweep, T_lidar_world, opt);
  // The ray work per object runs on all threads; each object's result depends only on its own rays.
  std::atomic<std::size_t> next{0};
  auto work = [&]() {
    for (std::size_t k = next++; k < out.size(); k = next++) {
      ObjectTruth& o = out[k];
      lidarVisibility(o, caster, sweep, T_world_lidar, ego_velocity, yaw_rate);
      cameraLabel(o, actors[o.actor], caster, cam, calib, T_world_lidar, T_lidar_world, opt, frame);
    }
  };
  std::vector<std::thread> pool;
  for (int t = 1; t < opt.threads; ++t) pool.emplace_back(work);
  work();
  for (auto& th : pool) th.join();
  return out;
}

}  // namespace sim
}  // namespace ret3d
