#include "ret3d/sim/simulator.h"

#include <chrono>
#include <cstdio>
#include <set>

#include "ret3d/core/log.h"
#include "ret3d/sim/actors.h"
#include "ret3d/sim/ground_truth.h"
#include "ret3d/sim/ray_caster.h"
#include "ret3d/sim/replay.h"
#include "ret3d/sim/scene.h"
#include "ret3d/sim/sequence_writer.h"

namespace ret3d {
namespace sim {


namespace {

// The sensor's pose on the vehicle, with the sequence's mounting error drawn from its own stream (seeded by the
// sequence) so the scene and traffic stay those of the seed.
Eigen::Isometry3d sensorMount(const SimConfig& cfg, const SensorModel& sensor, std::uint64_t seq_seed) {
  Eigen::Isometry3d T_base_lidar = Eigen::Isometry3d::Identity();
  T_base_lidar.translation() = Eigen::Vector3d(sensor.mount_x, 0, sensor.mount_height);
  if (cfg.mount_height_jitter > 0 || cfg.mount_tilt_jitter_deg > 0) {
    Rng mount(mix64(seq_seed ^ 0x6d6f756e74ULL));
    const double deg = M_PI / 180.0;
    T_base_lidar.translation().z() += mount.normal(0, cfg.mount_height_jitter);
    const double pitch = mount.normal(0, cfg.mount_tilt_jitter_deg) * deg;
    const double roll = mount.normal(0, cfg.mount_tilt_jitter_deg) * deg;
    T_base_lidar.linear() =
        (Eigen::AngleAxisd(pitch, Eigen::Vector3d::UnitY()) * Eigen::AngleAxisd(roll, Eigen::Vector3d::UnitX()))
            .toRotationMatrix();
  }
  return T_base_lidar;
}

// Replay: the scene laid along the replayed ego's ground poses (world = first LiDAR frame; the road resampled at
// >= 1 m spacing), nothing static on the replayed objects, and the traffic set to the replayed tracks.
void buildReplayScene(const ReplayData& replay, const Eigen::Isometry3d& T_base_lidar, const SimConfig& cfg,
                      const SensorModel& sensor, Rng& rng, Scene& scene, Traffic& traffic) {
  std::vector<Eigen::Isometry3d> ground;
  for (const auto& P : replay.lidar_poses) ground.push_back(P * T_base_lidar.inverse());
  std::vector<Eigen::Vector2d> path;
  std::vector<double> z;
  for (const auto& G : ground) {
    const Eigen::Vector2d p = G.translation().head<2>();
    if (path.empty() || (p - path.back()).norm() >= 1.0) {
      path.push_back(p);
      z.push_back(G.translation().z());
    }
  }
  if (path.size() < 2) {
    // A (nearly) stationary ego: a straight road along its heading.
    const Eigen::Vector3d h = ground.front().linear().col(0);
    const Eigen::Vector2d p0 = ground.front().translation().head<2>();
    path = {p0, p0 + Eigen::Vector2d(h.x(), h.y()).normalized() * 2.0};
    z = {ground.front().translation().z(), ground.front().translation().z()};
  }
  layoutRoads(scene, cfg, rng, Path(path).length(), &path, &z);
  std::vector<Box> keep_out;
  for (const Actor& a : replay.actors)
    for (std::size_t f = 0; f < a.replay.size(); f += 3)
      if (a.replay[f]) keep_out.push_back(*a.replay[f]);
  buildStaticGeometry(scene, cfg, rng, sensor.max_range, keep_out);
  traffic.setReplay(replay.actors, ground);
}

// The actors' meshes at their poses into the caster; those beyond the sensor's range (+ 10 m) are left out.
void placeActors(const Traffic& traffic, const Eigen::Isometry3d& T, double max_range, RayCaster& caster) {
  for (std::size_t i = 0; i < traffic.actors.size(); ++i) {
    const Actor& a = traffic.actors[i];
    const bool near = a.active && (Eigen::Vector2d(a.x, a.y) - T.translation().head<2>()).norm() < max_range + 10;
    caster.setActor(i, a.mesh, actorPose(a), near, a.variant());
  }
  caster.commit();
}

// The sweep's returns as a cloud (ring = slot % beams, with their times).
PointCloud returnedPoints(const Sweep& sweep) {
  PointCloud cloud;
  cloud.points.reserve(sweep.size());
  for (std::size_t slot = 0; slot < sweep.size(); ++slot) {
    if (!sweep.returned[slot]) continue;
    cloud.push_back(sweep.points[slot], sweep.time[slot], static_cast<std::uint16_t>(slot % sweep.beams), true);
  }
  return cloud;
}

// The frame's labels counted into the frame's and the sequence's report (objects per class, tracks, returns).
void countLabels(const std::vector<ObjectTruth>& truth, FrameReport& fr, SequenceReport& report,
                 std::set<std::pair<std::string, std::uint32_t>>& tracks) {
  fr.objects = truth.size();
  for (const ObjectTruth& o : truth) {
    const std::string cls = o.label.type;  // Car, Pedestrian, Cyclist, and Van or Truck
    ++report.objects[cls];
    tracks.insert({cls, o.box.track_id});
    report.object_points += o.box.num_points;
    if (std::hypot(o.box.x, o.box.y) <= 50.0) ++fr.objects_within_50m;
  }
}

}  // namespace

SequenceReport simulateSequence(const SimOptions& opt, int index,
                                const std::function<void(const FrameReport&)>& on_frame) {
  using Clock = std::chrono::steady_clock;
  const auto t_setup = Clock::now();
  const SimConfig& cfg = opt.config;
  const SensorModel& sensor = opt.sensor;
  SequenceReport report;
  char seq[16];
  std::snprintf(seq, sizeof(seq), "%04d", index);
  report.name = seq;
  const std::uint64_t seq_seed = opt.seed + static_cast<std::uint64_t>(index);
  Rng rng(seq_seed);
  const double dt = 1.0 / cfg.frame_rate;
  const Eigen::Isometry3d T_base_lidar = sensorMount(cfg, sensor, seq_seed);

  Scene scene;
  Traffic traffic(cfg, scene);
  kitti::Calibration calib = kitti::defaultCalibration();
  TruthOptions topt;
  topt.label_range = cfg.label_range;
  topt.min_points = cfg.label_min_points;
  topt.threads = opt.threads;
  int frames = opt.frames;
  ReplayData replay;
  const bool replaying = !opt.replay_dir.empty();
  if (replaying) {
    replay = loadReplay(opt.replay_dir, opt.replay_sequence, cfg, rng, opt.frames);
    frames = replay.frames;
    calib = replay.calib;
    // Every replayed object is labelled, whatever its range and returns: the output reproduces the input tracks.
    topt.label_range = 1e9;
    topt.min_points = 0;
    buildReplayScene(replay, T_base_lidar, cfg, sensor, rng, scene, traffic);
  } else {
    const double reach = cfg.traffic.ego_speed.hi * frames * dt + 10;
    layoutRoads(scene, cfg, rng, reach);
    buildStaticGeometry(scene, cfg, rng, sensor.max_range, {});
    traffic.spawn(rng, sensor.max_range);
  }
  report.static_triangles = scene.mesh.size();

  RayCaster caster(sensor, opt.threads);
  caster.setStatic(scene.mesh);
  SequenceWriter writer(opt.out_dir, seq, calib);
  if (replaying) writer.setCameraPoses(replay.camera_poses);
  report.setup_seconds = std::chrono::duration<double>(Clock::now() - t_setup).count();

  std::set<std::pair<std::string, std::uint32_t>> tracks;
  Eigen::Isometry3d T0_inv = Eigen::Isometry3d::Identity(), prev = Eigen::Isometry3d::Identity();
  for (int f = 0; f < frames; ++f) {
    const auto t0 = Clock::now();
    if (f > 0 || replaying) traffic.step((f - 1) * dt, dt, f, rng);
    const Eigen::Isometry3d T = traffic.egoPose() * T_base_lidar;
    if (f == 0) {
      T0_inv = T.inverse();
      prev = T;
    }
    placeActors(traffic, T, sensor.max_range, caster);
    // Ego motion in the LiDAR frame (for motion distortion): from the previous frame's pose.
    const Eigen::Isometry3d step = prev.inverse() * T;
    const Eigen::Vector3d v = f > 0 ? Eigen::Vector3d(step.translation() / dt) : Eigen::Vector3d(traffic.ego.v, 0, 0);
    const double w = f > 0 ? std::atan2(step.linear()(1, 0), step.linear()(0, 0)) / dt : 0.0;
    prev = T;
    const Sweep sweep = caster.cast(T, mix64(seq_seed), f, v, w);
    std::vector<ObjectTruth> truth = labelFrame(traffic.actors, caster, sweep, T, calib, topt, f, v, w);
    const PointCloud cloud = returnedPoints(sweep);
    writer.writeFrame(f, cloud, truth, T0_inv * T);
    FrameReport fr;
    fr.sequence = index;
    fr.frame = f;
    fr.points = cloud.size();
    countLabels(truth, fr, report, tracks);
    fr.seconds = std::chrono::duration<double>(Clock::now() - t0).count();
    report.frames.push_back(fr);
    if (on_frame) on_frame(fr);
  }
  writer.finish();
  for (const auto& [cls, id] : tracks) ++report.tracks[cls];
  return report;
}

}  // namespace sim
}  // namespace ret3d
