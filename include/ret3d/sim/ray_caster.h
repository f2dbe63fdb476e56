// Embree 3 ray casting of a spinning LiDAR through a scene: the static geometry is one BVH built once per sequence
// and instanced; every actor is its own small scene instanced with its pose, re-committed per frame (articulated
// actors also update their vertices). A sweep is cast on all threads in packets of 16 rays (rtcIntersect16, one
// packet = 16 beams of one firing); each ray's noise comes from a hash of (seed, frame, ray), and each thread writes
// only its own rays' slots, so the output does not depend on thread scheduling.
#pragma once

#include <memory>
#include <vector>

#include <Eigen/Geometry>

#include "ret3d/core/types.h"
#include "ret3d/sim/mesh.h"
#include "ret3d/sim/sensor_model.h"

namespace ret3d {
namespace sim {

// One sweep: a slot per ray (column-major: slot = column * beams + beam).
struct Sweep {
  int columns = 0, beams = 0;
  std::vector<Point> points;          // in the LiDAR frame (valid where returned)
  std::vector<float> time;            // firing time within the sweep (s)
  std::vector<std::int32_t> actor;    // actor index the ray hit first (-1: static scene or nothing)
  std::vector<std::uint8_t> hit;      // the ray hit something within range
  std::vector<std::uint8_t> returned; // and the return survived drop-out
  std::size_t size() const { return points.size(); }
};

class RayCaster {
 public:
  explicit RayCaster(const SensorModel& sensor, int threads = 2);
  ~RayCaster();
  RayCaster(const RayCaster&) = delete;
  RayCaster& operator=(const RayCaster&) = delete;

  const SensorModel& sensor() const { return sensor_; }
  // The static scene (once per sequence).
  void setStatic(const TriangleMesh& mesh);
  // Actor i's mesh (in its own frame) and world pose; `active` false removes it from this frame. Each (actor,
  // variant) gets its BVH the first time it is seen; later frames with the same variant only move the instance, so an
  // articulated actor cycling through its quantised poses costs no rebuilds.
  void setActor(std::size_t i, const TriangleMesh& mesh, const Eigen::Isometry3d& pose, bool active, int variant = 0);
  // Commits the frame's changes.
  void commit();

  // Casts a sweep from the LiDAR pose in the world. `ego_velocity` (m/s, LiDAR frame) and `yaw_rate` (rad/s) move the
  // sensor within the sweep when the model has motion distortion; the pose is the sensor's at mid-sweep.
  Sweep cast(const Eigen::Isometry3d& T_world_lidar, std::uint64_t seed, int frame,
             const Eigen::Vector3d& ego_velocity = Eigen::Vector3d::Zero(), double yaw_rate = 0) const;

  // The world ray of one slot (origin, unit direction), as cast by `cast`.
  void slotRay(const Eigen::Isometry3d& T_world_lidar, int column, int beam, const Eigen::Vector3d& ego_velocity,
               double yaw_rate, Eigen::Vector3d* origin, Eigen::Vector3d* dir) const;
  // Distance along a world ray to the first hit, and the actor hit (-1 static); false when nothing within [tnear, tfar].
  bool intersect(const Eigen::Vector3d& origin, const Eigen::Vector3d& dir, double tnear, double tfar, double* t,
                 int* actor) const;
  // Whether the ray hits actor i's mesh alone (ignoring everything else).
  bool intersectActorOnly(std::size_t i, const Eigen::Vector3d& origin, const Eigen::Vector3d& dir, double tnear,
                          double tfar) const;
  // Unit beam direction in the LiDAR frame, and the firing time of a column.
  Eigen::Vector3d beamDirection(int column, int beam) const;
  double columnTime(int column) const;
  double columnAzimuth(int column) const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
  SensorModel sensor_;
};

}  // namespace sim
}  // namespace ret3d
