#include "ret3d/sim/replay.h"

#include <filesystem>
#include <map>
#include <stdexcept>

#include "ret3d/core/transform.h"

namespace ret3d {
namespace sim {

ReplayData loadReplay(const std::string& root, const std::string& sequence, const SimConfig& config, Rng& rng,
                      int max_frames) {
  kitti::TrackingDataset ds(root);
  ReplayData out;
  for (const auto& [what, path] : {std::pair<const char*, std::string>{"labels", ds.labelPath(sequence)},
                                   {"poses", ds.posePath(sequence)}, {"calibration", ds.calibPath(sequence)}}) {
    if (!std::filesystem::exists(path))
      throw std::runtime_error(std::string("replay: no ") + what + " for sequence " + sequence + " (" + path + ")");
  }
  out.calib = kitti::readCalibration(ds.calibPath(sequence));
  out.camera_poses = kitti::readPoses(ds.posePath(sequence));
  out.lidar_poses = kitti::cameraPosesToLidar(out.camera_poses, out.calib);
  const std::vector<kitti::Label> labels = kitti::readTrackingLabels(ds.labelPath(sequence));
  out.frames = static_cast<int>(out.lidar_poses.size());
  if (max_frames > 0) out.frames = std::min(out.frames, max_frames);
  if (out.frames <= 0) throw std::runtime_error("replay: sequence " + sequence + " has no poses");
  out.camera_poses.resize(out.frames);
  out.lidar_poses.resize(out.frames);

  std::map<int, std::size_t> index;  // KITTI track id -> actor
  for (const kitti::Label& l : labels) {
    if (l.frame < 0 || l.frame >= out.frames || l.track_id < 0) continue;
    ActorKind kind;
    if (l.type == "Car") kind = ActorKind::Car;
    else if (l.type == "Pedestrian") kind = ActorKind::Pedestrian;
    else if (l.type == "Cyclist") kind = ActorKind::Cyclist;
    else if (l.type == "Van" || l.type == "Truck") kind = ActorKind::Obstacle;
    else continue;
    auto it = index.find(l.track_id);
    if (it == index.end()) {
      Actor a;
      a.kind = kind;
      a.labelled = kind != ActorKind::Obstacle;
      a.track_id = static_cast<std::uint32_t>(l.track_id) + 1u;  // unsigned: a track id of INT_MAX must not overflow
      drawCar(a, config, rng);  // surfaces (and a body for vehicles)
      a.kind = kind;
      a.length = l.l;
      a.width = l.w;
      a.height = l.h;
      if (kind == ActorKind::Obstacle) a.body = CarBody::Van;
      if (kind == ActorKind::Pedestrian) {
        a.stature = std::max(1.0, l.h - kLabelMargin);
        a.breadth = std::clamp(0.7 * l.w, 0.3, 0.55);
        a.swing_max = 0.35;
      } else if (kind == ActorKind::Cyclist) {
        a.stature = std::max(1.2, l.h - 0.0);
        // The handlebars span the label's width less the rider's hands and the margins.
        a.bar_width = std::clamp(l.w - 0.19, 0.38, 0.72);
        a.breadth = 0.34;
      }
      a.mesh = actorMesh(a);
      a.replay.assign(out.frames, std::nullopt);
      it = index.emplace(l.track_id, out.actors.size()).first;
      out.actors.push_back(std::move(a));
    }
    Box b = kitti::labelToBox(l, out.calib);
    b.label = out.actors[it->second].objectClass();
    out.actors[it->second].replay[l.frame] = transformBox(b, out.lidar_poses[l.frame]);
  }
  return out;
}

}  // namespace sim
}  // namespace ret3d
