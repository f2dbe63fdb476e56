// Actors and their motion: the ego vehicle, moving and parked cars, walking, standing and crossing pedestrians, and
// cyclists. Vehicles and cyclists follow lanes with an intelligent-driver model (IDM: Treiber et al. 2000), obey the
// traffic lights of intersections, change their target speed now and then, stop, and turn right; pedestrians walk
// along sidewalks and across the road. Every move is checked against every other actor's box and the ego's, so
// actors never interpenetrate (an actor that would overlap stays where it is for that step).
#pragma once

#include <memory>
#include <optional>
#include <string>
#include <unordered_map>
#include <vector>

#include "ret3d/core/types.h"
#include "ret3d/sim/actor_meshes.h"
#include "ret3d/sim/path.h"
#include "ret3d/sim/random.h"
#include "ret3d/sim/scene.h"
#include "ret3d/sim/sim_config.h"

namespace ret3d {
namespace sim {

inline constexpr int kPhaseSteps = 16;

// Obstacle: a vehicle of another KITTI class (a replayed Van/Truck, drawn, not labelled; a generated truck or delivery
// van, labelled with its `kitti_type`).
enum class ActorKind { Car, Pedestrian, Cyclist, Obstacle };

struct Actor {
  std::uint32_t track_id = 0;   // 1-based and unique in the sequence; the KITTI track id is track_id - 1
  ActorKind kind = ActorKind::Car;
  CarBody body = CarBody::Sedan;
  bool labelled = true;
  std::string kitti_type;       // the label_02 type of an Obstacle ("Van", "Truck"); empty = from the class
  bool queued = false;          // in a stop-and-go queue (TrafficConfig::queue): creeps, stops, keeps `jam_gap`
  double jam_gap = -1;          // IDM jam distance (m); < 0 = the kind's
  // Label box size and where its centre sits in the actor frame (x forward; the mesh origin is on the ground).
  double length = 4, width = 1.7, height = 1.5;
  Eigen::Vector2d box_offset = Eigen::Vector2d::Zero();
  double stature = 1.75, breadth = 0.45, swing_max = 0.4;  // pedestrians and riders (a rider's breadth: the torso's)
  double depth = 0.27;          // pedestrians: chest to back, clothes included
  double bar_width = 0.54, lean = 0.75;  // cyclists: handlebars across (m), torso forward of vertical (rad)
  bool backpack = false;        // pedestrians
  double phase = 0;             // gait or crank angle
  ActorSurfaces surfaces;

  // Motion along a path.
  std::shared_ptr<const Path> path;
  double s = 0, v = 0, v_cruise = 0, v_target = 0, next_change = 0, stop_until = -1;
  bool moving = true;           // parked cars and standing pedestrians do not move
  bool active = true;           // in the scene (false once it leaves its path's end, or absent in a replay frame)
  struct Stop {
    double s;                   // stop line station on the path
    int intersection;
    bool main_approach;
  };
  std::vector<Stop> stops;

  // Pose in the world: ground point below the mesh origin, heading, velocity over ground.
  double x = 0, y = 0, z = 0, yaw = 0, vx = 0, vy = 0;

  // Replay: the world box at each frame (nullopt when not labelled in that frame).
  std::vector<std::optional<Box>> replay;

  TriangleMesh mesh;            // in the actor frame, current articulation
  bool articulated() const { return kind == ActorKind::Pedestrian || kind == ActorKind::Cyclist; }
  // Which of the actor's mesh poses is current: the gait or crank phase quantised to kPhaseSteps steps per cycle
  // (kPhaseSteps for a pedestrian standing still; always 0 for vehicles). The ray caster keeps one BVH per variant.
  int variant() const;
  ObjectClass objectClass() const;
};

// The label box of an actor in the world frame (with velocity, class, track id).
Box worldBox(const Actor& a);
// The actor frame in the world: ground point below the mesh origin, heading about z.
Eigen::Isometry3d actorPose(const Actor& a);
// The actor's mesh for its current phase (cars: the fixed body).
TriangleMesh actorMesh(const Actor& a);
// A car body type and label size drawn from the config's mix, around KITTI's Car distribution.
void drawCar(Actor& a, const SimConfig& config, Rng& rng);
// A vehicle: a truck or a delivery van with the config's probabilities (KITTI Truck / Van), else a car (drawCar).
void drawVehicle(Actor& a, const SimConfig& config, Rng& rng);
// A car paint reflectivity from the config's colour mixture (SimConfig::paint); without one, the `paint` material.
double drawPaint(const SimConfig& config, Rng& rng);

class Traffic {
 public:
  Traffic(const SimConfig& config, const Scene& scene);

  // Places the ego and draws every other actor (generated scenes).
  void spawn(Rng& rng, double view_range);
  // Adds replayed actors (their world boxes per frame) and the ego path (world poses of the ego ground point).
  void setReplay(std::vector<Actor> actors, std::vector<Eigen::Isometry3d> ego_poses);
  // Advances to time t (seconds from the start) by dt; in replay, jumps to `frame`.
  void step(double t, double dt, int frame, Rng& rng);

  Actor ego;
  std::vector<Actor> actors;
  bool replaying() const { return replay_; }
  // The ego's ground pose (x forward, z up) in the world at the current step.
  Eigen::Isometry3d egoPose() const;

 private:
  // spawn() in parts; they draw from rng in this order: the ego, then lane by lane its parked cars, moving cars,
  // cyclists or pedestrians. Actors far from the ego's `route` are not drawn.
  void spawnEgo(Rng& rng);
  // Stop-and-go queues in every lane of the ego's direction, the ego standing in one (TrafficConfig::queue); the
  // vehicle right ahead of the ego is a car.
  void spawnQueues(Rng& rng);
  void spawnParked(const Lane& l, const Path& route, double view_range, Rng& rng);
  void spawnCars(const Lane& l, Rng& rng);
  void spawnCyclists(const Lane& l, const Path& route, double view_range, Rng& rng);
  void spawnPedestrians(const Lane& l, const Path& route, double view_range, Rng& rng);
  void planRightTurn(Actor& a, const Lane& l) const;  // at the next intersection ahead, when a lane leads right
  void planCrossing(Actor& a, const Lane& l) const;   // across the main road at the next zebra crossing ahead
  bool nearCrossing(const Eigen::Vector2d& p, double d) const;  // within d (m, along the main road) of a zebra crossing
  // Places a and adds it unless it overlaps static geometry, another actor or the ego.
  void tryAdd(Actor a);
  void place(Actor& a);  // pose from path and station
  void advance(Actor& a, double t, double dt, Rng& rng);
  double leaderGap(const Actor& a, double horizon, double* leader_speed) const;
  bool overlapsAny(const Actor& a, const Box& b) const;
  void findStops(Actor& a) const;
  bool green(int intersection, bool main_approach, double t) const;
  // Actors near a point (grid of actor positions at the start of each sub-step; -1 is the ego).
  void buildGrid();
  std::vector<int> near(double x, double y, double radius) const;
  std::unordered_map<long long, std::vector<int>> grid_;
  static constexpr double kCell = 10.0;
  std::uint32_t next_id_ = 1;
  const SimConfig& config_;
  const Scene& scene_;
  bool replay_ = false;
  std::vector<Eigen::Isometry3d> ego_poses_;
  Eigen::Isometry3d ego_pose_ = Eigen::Isometry3d::Identity();
};

}  // namespace sim
}  // namespace ret3d
