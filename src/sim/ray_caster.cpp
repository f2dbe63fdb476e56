#include "ret3d/sim/ray_caster.h"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstring>
#include <map>
#include <stdexcept>
#include <string>
#include <thread>

#include <embree3/rtcore.h>

#include "ret3d/sim/random.h"

namespace ret3d {
namespace sim {

namespace {

RTCGeometry makeMesh(RTCDevice device, const TriangleMesh& mesh) {
  RTCGeometry g = rtcNewGeometry(device, RTC_GEOMETRY_TYPE_TRIANGLE);
  auto* vb = static_cast<float*>(rtcSetNewGeometryBuffer(g, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3,
                                                         3 * sizeof(float), mesh.vertices.size()));
  for (std::size_t i = 0; i < mesh.vertices.size(); ++i) {
    vb[3 * i] = mesh.vertices[i].x();
    vb[3 * i + 1] = mesh.vertices[i].y();
    vb[3 * i + 2] = mesh.vertices[i].z();
  }
  auto* ib = static_cast<unsigned*>(rtcSetNewGeometryBuffer(g, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3,
                                                            3 * sizeof(unsigned), mesh.triangles.size()));
  for (std::size_t i = 0; i < mesh.triangles.size(); ++i)
    for (int k = 0; k < 3; ++k) ib[3 * i + k] = mesh.triangles[i][k];
  rtcCommitGeometry(g);
  return g;
}

// A committed scene holding the mesh alone (to be instanced).
RTCScene meshScene(RTCDevice device, const TriangleMesh& mesh, RTCBuildQuality quality) {
  RTCScene scene = rtcNewScene(device);
  rtcSetSceneBuildQuality(scene, quality);
  RTCGeometry g = makeMesh(device, mesh);
  rtcAttachGeometry(scene, g);
  rtcReleaseGeometry(g);
  rtcCommitScene(scene);
  return scene;
}

void setTransform(RTCGeometry inst, const Eigen::Isometry3d& T) {
  float m[12];
  const Eigen::Matrix<double, 3, 4> M = T.matrix().topRows<3>();
  for (int c = 0; c < 4; ++c)
    for (int r = 0; r < 3; ++r) m[3 * c + r] = static_cast<float>(M(r, c));
  rtcSetGeometryTransform(inst, 0, RTC_FORMAT_FLOAT3X4_COLUMN_MAJOR, m);
}

}  // namespace

struct RayCaster::Impl {
  RTCDevice device = nullptr;
  RTCScene top = nullptr;
  RTCScene static_scene = nullptr;
  RTCGeometry static_inst = nullptr;
  std::vector<Surface> static_surfaces;
  struct Variant {
    RTCScene scene = nullptr;
    std::vector<Surface> surfaces;
  };
  struct ActorGeom {
    std::map<int, Variant> variants;
    int current = -1;
    RTCScene scene = nullptr;  // the current variant's
    const std::vector<Surface>* surfaces = nullptr;
    RTCGeometry inst = nullptr;
    Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
    bool enabled = false;
  };
  std::vector<ActorGeom> actors;
  std::vector<Eigen::Vector3f> dirs;  // per slot, LiDAR frame
  std::vector<float> col_time;
  std::vector<std::uint8_t> ego_blocked;  // per slot: the ray passes through the ego's body
  int threads = 2;

  ~Impl() {
    for (auto& a : actors)
      for (auto& [k, v] : a.variants) rtcReleaseScene(v.scene);
    if (top) rtcReleaseScene(top);
    if (static_scene) rtcReleaseScene(static_scene);
    if (device) rtcReleaseDevice(device);
  }
};

RayCaster::RayCaster(const SensorModel& sensor, int threads) : impl_(std::make_unique<Impl>()), sensor_(sensor) {
  impl_->threads = std::max(1, threads);
  const std::string cfg = "threads=" + std::to_string(impl_->threads);
  impl_->device = rtcNewDevice(cfg.c_str());
  if (!impl_->device) throw std::runtime_error("Embree: cannot create a device");
  impl_->top = rtcNewScene(impl_->device);
  rtcSetSceneBuildQuality(impl_->top, RTC_BUILD_QUALITY_LOW);
  rtcSetSceneFlags(impl_->top, RTC_SCENE_FLAG_DYNAMIC);
  const int cols = sensor_.columns(), beams = sensor_.beams();
  impl_->dirs.resize(static_cast<std::size_t>(cols) * beams);
  impl_->col_time.resize(cols);
  impl_->ego_blocked.assign(impl_->dirs.size(), 0);
  for (int c = 0; c < cols; ++c) {
    impl_->col_time[c] = static_cast<float>(columnTime(c));
    for (int b = 0; b < beams; ++b) {
      const Eigen::Vector3d d = beamDirection(c, b);
      impl_->dirs[static_cast<std::size_t>(c) * beams + b] = d.cast<float>();
      impl_->ego_blocked[static_cast<std::size_t>(c) * beams + b] = sensor_.blockedByEgoBody(d.x(), d.y(), d.z());
    }
  }
}

RayCaster::~RayCaster() = default;

double RayCaster::columnAzimuth(int column) const {
  // Clockwise from behind (as a Velodyne turns, seen from above), so the sweep starts and ends at the rear.
  return M_PI - (column + 0.5) * 2.0 * M_PI / sensor_.columns();
}

double RayCaster::columnTime(int column) const { return sensor_.period() * (column + 0.5) / sensor_.columns(); }

Eigen::Vector3d RayCaster::beamDirection(int column, int beam) const {
  const double az = columnAzimuth(column), el = sensor_.elevation_deg[beam] * M_PI / 180.0;
  return {std::cos(el) * std::cos(az), std::cos(el) * std::sin(az), std::sin(el)};
}

void RayCaster::setStatic(const TriangleMesh& mesh) {
  Impl& m = *impl_;
  if (m.static_scene) {
    rtcDetachGeometry(m.top, 0);
    rtcReleaseScene(m.static_scene);
  }
  m.static_scene = meshScene(m.device, mesh, RTC_BUILD_QUALITY_HIGH);
  m.static_surfaces = mesh.surfaces;
  m.static_inst = rtcNewGeometry(m.device, RTC_GEOMETRY_TYPE_INSTANCE);
  rtcSetGeometryInstancedScene(m.static_inst, m.static_scene);
  setTransform(m.static_inst, Eigen::Isometry3d::Identity());
  rtcCommitGeometry(m.static_inst);
  rtcAttachGeometryByID(m.top, m.static_inst, 0);
  rtcReleaseGeometry(m.static_inst);
}

void RayCaster::setActor(std::size_t i, const TriangleMesh& mesh, const Eigen::Isometry3d& pose, bool active,
                         int variant) {
  Impl& m = *impl_;
  if (m.actors.size() <= i) m.actors.resize(i + 1);
  Impl::ActorGeom& a = m.actors[i];
  if (!active) {
    if (a.inst && a.enabled) {
      rtcDisableGeometry(a.inst);
      rtcCommitGeometry(a.inst);
      a.enabled = false;
    }
    return;
  }
  auto it = a.variants.find(variant);
  if (it == a.variants.end()) {
    Impl::Variant v;
    v.scene = meshScene(m.device, mesh, RTC_BUILD_QUALITY_MEDIUM);
    v.surfaces = mesh.surfaces;
    it = a.variants.emplace(variant, std::move(v)).first;
  }
  if (!a.inst) {
    a.inst = rtcNewGeometry(m.device, RTC_GEOMETRY_TYPE_INSTANCE);
    rtcSetGeometryInstancedScene(a.inst, it->second.scene);
    rtcAttachGeometryByID(m.top, a.inst, static_cast<unsigned>(i + 1));
    rtcReleaseGeometry(a.inst);
    a.enabled = true;
  } else {
    if (a.current != variant) rtcSetGeometryInstancedScene(a.inst, it->second.scene);
    if (!a.enabled) {
      rtcEnableGeometry(a.inst);
      a.enabled = true;
    }
  }
  a.current = variant;
  a.scene = it->second.scene;
  a.surfaces = &it->second.surfaces;
  a.pose = pose;
  setTransform(a.inst, pose);
  rtcCommitGeometry(a.inst);
}

void RayCaster::commit() { rtcCommitScene(impl_->top); }

void RayCaster::slotRay(const Eigen::Isometry3d& T, int column, int beam, const Eigen::Vector3d& ego_velocity,
                        double yaw_rate, Eigen::Vector3d* origin, Eigen::Vector3d* dir) const {
  const Eigen::Vector3d d = impl_->dirs[static_cast<std::size_t>(column) * sensor_.beams() + beam].cast<double>();
  if (sensor_.motion_distortion) {
    const double dt = impl_->col_time[column] - 0.5 * sensor_.period();
    Eigen::Isometry3d D = Eigen::Isometry3d::Identity();
    D.translation() = ego_velocity * dt;
    D.linear() = Eigen::AngleAxisd(yaw_rate * dt, Eigen::Vector3d::UnitZ()).toRotationMatrix();
    const Eigen::Isometry3d Tt = T * D;
    *origin = Tt.translation();
    *dir = Tt.linear() * d;
  } else {
    *origin = T.translation();
    *dir = T.linear() * d;
  }
}

namespace {

// A sweep of cols x beams slots, none hit or returned yet.
Sweep emptySweep(int cols, int beams) {
  Sweep sw;
  sw.columns = cols;
  sw.beams = beams;
  const std::size_t n = static_cast<std::size_t>(cols) * beams;
  sw.points.resize(n);
  sw.time.resize(n);
  sw.actor.assign(n, -1);
  sw.hit.assign(n, 0);
  sw.returned.assign(n, 0);
  return sw;
}

// Ray k of a packet from o along d within [tnear, tfar], with no hit yet.
void setPacketRay(RTCRayHit16* rh, int k, const Eigen::Vector3d& o, const Eigen::Vector3d& d, float tnear, float tfar) {
  rh->ray.org_x[k] = static_cast<float>(o.x());
  rh->ray.org_y[k] = static_cast<float>(o.y());
  rh->ray.org_z[k] = static_cast<float>(o.z());
  rh->ray.dir_x[k] = static_cast<float>(d.x());
  rh->ray.dir_y[k] = static_cast<float>(d.y());
  rh->ray.dir_z[k] = static_cast<float>(d.z());
  rh->ray.tnear[k] = tnear;
  rh->ray.tfar[k] = tfar;
  rh->ray.time[k] = 0;
  rh->ray.mask[k] = 0xffffffffu;
  rh->ray.id[k] = static_cast<unsigned>(k);
  rh->ray.flags[k] = 0;
  rh->hit.geomID[k] = RTC_INVALID_GEOMETRY_ID;
  rh->hit.instID[0][k] = RTC_INVALID_GEOMETRY_ID;
}

// The sensor's response to a ray (from ray_org along ray_dir) that hit a surface with geometric normal ng at `range`:
// whether a return comes back (drop-out, porous crowns, range limits, the detection floor) and its range and
// intensity. Draws from rng in a fixed order.
bool sensorResponse(const RayCaster& caster, const SensorModel& sensor, const Surface& surf,
                    const Eigen::Vector3d& ray_org, const Eigen::Vector3d& ray_dir, const Eigen::Vector3d& ng,
                    double range, HashRng& rng, double* r_out, double* inten_out) {
  const double wd = ray_dir.normalized().dot(ng.normalized());
  const double cos_inc = std::min(1.0, std::abs(wd));
  const double keep = (1.0 - sensor.dropout) * (1.0 - surf.dropout) *
                      (1.0 - sensor.far_dropout * range / sensor.max_range) *
                      (cos_inc < 0.03 ? 0.0 : 1.0);
  if (rng.uniform() >= keep) return false;
  if (surf.porosity > 0 && rng.uniform() < surf.porosity) {
    // Into the crown: the return comes from a leaf at a random depth before the next surface.
    const Eigen::Vector3d wdir = ray_dir.normalized();
    double depth = kPorousDepth;
    caster.intersect(ray_org + wdir * (range + 1e-3), wdir, 0.0, kPorousDepth, &depth, nullptr);
    range += rng.uniform() * depth;
  }
  const double r = range + sensor.range_noise_sigma * rng.normal();
  if (r < sensor.min_range || r > sensor.max_range) return false;
  const double signal = surf.reflectivity * std::pow(cos_inc, sensor.incidence_exponent) *
                        std::exp(-sensor.range_attenuation * range) * sensor.intensity_gain;
  double inten = std::clamp(signal + sensor.intensity_noise_sigma * rng.normal(), 0.0, 1.0);
  if (inten < sensor.zero_intensity_below) inten = 0.0;
  if (sensor.weak_return_zero_below > 0) {
    // The detection floor (a draw only for weak returns, so brighter rays keep their noise).
    const WeakReturn weak = weakReturn(sensor, signal);
    if (weak.zero) inten = 0.0;
    if (weak.lost > 0 && rng.uniform() < weak.lost) return false;
  }
  if (sensor.zero_intensity_near > 0 || sensor.zero_intensity_far > 0) {
    const double ramp = std::clamp((r - sensor.zero_intensity_near_range) /
                                       (sensor.zero_intensity_far_range - sensor.zero_intensity_near_range),
                                   0.0, 1.0);
    const double p0 =
        sensor.zero_intensity_near + (sensor.zero_intensity_far - sensor.zero_intensity_near) * ramp;
    if (rng.uniform() < p0) inten = 0.0;
  }
  *r_out = r;
  *inten_out = inten;
  return true;
}

}  // namespace

Sweep RayCaster::cast(const Eigen::Isometry3d& T, std::uint64_t seed, int frame, const Eigen::Vector3d& ego_velocity,
                      double yaw_rate) const {
  const Impl& m = *impl_;
  const int cols = sensor_.columns(), beams = sensor_.beams();
  Sweep sw = emptySweep(cols, beams);
  const float tnear = static_cast<float>(sensor_.min_range), tfar = static_cast<float>(sensor_.max_range);
  std::atomic<int> next_block{0};
  const int block = 32;  // columns per work item
  const int blocks = (cols + block - 1) / block;
  auto worker = [&]() {
    RTCIntersectContext ctx;
    rtcInitIntersectContext(&ctx);
    ctx.flags = RTC_INTERSECT_CONTEXT_FLAG_COHERENT;
    alignas(64) RTCRayHit16 rh;
    alignas(64) int valid[16];
    for (int bi = next_block++; bi < blocks; bi = next_block++) {
      for (int c = bi * block; c < std::min(cols, (bi + 1) * block); ++c) {
        for (int b0 = 0; b0 < beams; b0 += 16) {
          for (int k = 0; k < 16; ++k) {
            const int b = b0 + k;
            valid[k] = b < beams && !m.ego_blocked[static_cast<std::size_t>(c) * beams + b] ? -1 : 0;
            Eigen::Vector3d o(0, 0, 0), d(1, 0, 0);
            if (b < beams) slotRay(T, c, b, ego_velocity, yaw_rate, &o, &d);
            setPacketRay(&rh, k, o, d, tnear, tfar);
          }
          rtcIntersect16(valid, m.top, &ctx, &rh);
          for (int k = 0; k < 16 && b0 + k < beams; ++k) {
            const int b = b0 + k;
            const std::size_t slot = static_cast<std::size_t>(c) * beams + b;
            sw.time[slot] = m.col_time[c];
            if (!valid[k] || rh.hit.geomID[k] == RTC_INVALID_GEOMETRY_ID) continue;
            const unsigned inst = rh.hit.instID[0][k];
            const unsigned prim = rh.hit.primID[k];
            Surface surf;
            Eigen::Vector3d ng(rh.hit.Ng_x[k], rh.hit.Ng_y[k], rh.hit.Ng_z[k]);
            int actor = -1;
            if (inst == 0 || inst == RTC_INVALID_GEOMETRY_ID) {
              if (prim < m.static_surfaces.size()) surf = m.static_surfaces[prim];
            } else {
              actor = static_cast<int>(inst) - 1;
              const Impl::ActorGeom& ag = m.actors[actor];
              if (ag.surfaces && prim < ag.surfaces->size()) surf = (*ag.surfaces)[prim];
              ng = ag.pose.linear() * ng;  // Embree reports instanced normals in object space
            }
            double range = rh.ray.tfar[k];
            sw.hit[slot] = 1;
            sw.actor[slot] = actor;
            // Per-ray randomness from (seed, frame, slot): independent of threads and order.
            HashRng rng(seed, static_cast<std::uint64_t>(frame), slot);
            const Eigen::Vector3d d = m.dirs[slot].cast<double>();
            double r = 0, inten = 0;
            if (!sensorResponse(*this, sensor_, surf,
                                Eigen::Vector3d(rh.ray.org_x[k], rh.ray.org_y[k], rh.ray.org_z[k]),
                                Eigen::Vector3d(rh.ray.dir_x[k], rh.ray.dir_y[k], rh.ray.dir_z[k]), ng, range, rng, &r,
                                &inten))
              continue;
            Point& p = sw.points[slot];
            p.x = static_cast<float>(d.x() * r);
            p.y = static_cast<float>(d.y() * r);
            p.z = static_cast<float>(d.z() * r);
            p.intensity = static_cast<float>(inten);
            sw.returned[slot] = 1;
          }
        }
      }
    }
  };
  std::vector<std::thread> pool;
  for (int t = 1; t < m.threads; ++t) pool.emplace_back(worker);
  worker();
  for (auto& th : pool) th.join();
  return sw;
}

bool RayCaster::intersect(const Eigen::Vector3d& origin, const Eigen::Vector3d& dir, double tnear, double tfar,
                          double* t, int* actor) const {
  RTCIntersectContext ctx;
  rtcInitIntersectContext(&ctx);
  RTCRayHit rh;
  rh.ray.org_x = static_cast<float>(origin.x());
  rh.ray.org_y = static_cast<float>(origin.y());
  rh.ray.org_z = static_cast<float>(origin.z());
  rh.ray.dir_x = static_cast<float>(dir.x());
  rh.ray.dir_y = static_cast<float>(dir.y());
  rh.ray.dir_z = static_cast<float>(dir.z());
  rh.ray.tnear = static_cast<float>(tnear);
  rh.ray.tfar = static_cast<float>(tfar);
  rh.ray.time = 0;
  rh.ray.mask = 0xffffffffu;
  rh.ray.id = 0;
  rh.ray.flags = 0;
  rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
  rh.hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
  rtcIntersect1(impl_->top, &ctx, &rh);
  if (rh.hit.geomID == RTC_INVALID_GEOMETRY_ID) return false;
  if (t) *t = rh.ray.tfar;
  if (actor) *actor = (rh.hit.instID[0] == 0 || rh.hit.instID[0] == RTC_INVALID_GEOMETRY_ID) ? -1 : static_cast<int>(rh.hit.instID[0]) - 1;
  return true;
}

bool RayCaster::intersectActorOnly(std::size_t i, const Eigen::Vector3d& origin, const Eigen::Vector3d& dir,
                                   double tnear, double tfar) const {
  if (i >= impl_->actors.size() || !impl_->actors[i].scene) return false;
  const Impl::ActorGeom& a = impl_->actors[i];
  const Eigen::Isometry3d inv = a.pose.inverse();
  const Eigen::Vector3d o = inv * origin, d = inv.linear() * dir;
  RTCIntersectContext ctx;
  rtcInitIntersectContext(&ctx);
  RTCRay ray;
  ray.org_x = static_cast<float>(o.x());
  ray.org_y = static_cast<float>(o.y());
  ray.org_z = static_cast<float>(o.z());
  ray.dir_x = static_cast<float>(d.x());
  ray.dir_y = static_cast<float>(d.y());
  ray.dir_z = static_cast<float>(d.z());
  ray.tnear = static_cast<float>(tnear);
  ray.tfar = static_cast<float>(tfar);
  ray.time = 0;
  ray.mask = 0xffffffffu;
  ray.id = 0;
  ray.flags = 0;
  rtcOccluded1(a.scene, &ctx, &ray);
  return ray.tfar < 0;  // rtcOccluded1 sets tfar to -inf on a hit
}

}  // namespace sim
}  // namespace ret3d
