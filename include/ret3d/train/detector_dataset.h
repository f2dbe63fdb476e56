// Training samples for the base detector from KITTI tracking-layout folders (real or simulated): two consecutive
// sweeps, the ego motion between them (LiDAR poses), and the labelled boxes with velocities from their track ids.
#pragma once

#include <random>
#include <string>
#include <vector>

#include <Eigen/Geometry>

#include "ret3d/core/types.h"
#include "ret3d/detector/detector_options.h"

namespace ret3d {

struct DetectorSample {
  std::string id;                  // "SSSS/FFFFFF"
  PointCloud current;
  PointCloud previous;             // empty for the first frame of a sequence
  bool has_previous = false;
  Eigen::Isometry3d prev_to_current = Eigen::Isometry3d::Identity();
  std::vector<Box> boxes;          // the model's classes, LiDAR frame, velocity in m/s
  std::vector<bool> velocity_valid;
  std::vector<Box> ignore;         // DontCare, and the classes KITTI ignores for ours (Van for Car, ...)
};

class DetectorDataset {
 public:
  // Indexes every frame with a scan (labels are read now; scans on load()) of one or more folders, e.g. urban and
  // highway simulations. Throws when they have no labelled sequences.
  DetectorDataset(const std::vector<std::string>& roots, const ModelConfig& model, int max_frames = 0);
  DetectorDataset(const std::string& root, const ModelConfig& model, int max_frames = 0)
      : DetectorDataset(std::vector<std::string>{root}, model, max_frames) {}
  std::size_t size() const { return frames_.size(); }
  DetectorSample load(std::size_t i) const;
  // Every labelled box of the model's classes (for the k-means anchors).
  std::vector<Box> allBoxes() const;

 private:
  struct Frame {
    std::size_t seq;  // index into seqs_
    int frame;
    int previous;     // -1 when none
  };
  struct Sequence {
    std::string root;                            // the dataset folder it belongs to
    std::string name;
    std::vector<Eigen::Isometry3d> poses;       // T_velo0_velo_t, empty when absent
    std::vector<std::vector<Box>> boxes;         // per frame index: every labelled box (class Unknown for others)
    std::vector<std::vector<std::string>> types; // the KITTI type of each box
    std::vector<std::vector<bool>> velocity_valid;  // per box: its velocity came from its track
  };
  void addRoot(const std::string& root);
  Eigen::Isometry3d motion(const Sequence& s, int from, int to) const;  // T_to_from
  ModelConfig model_;
  std::vector<Sequence> seqs_;
  std::vector<Frame> frames_;
};

// Augmentation (LWD-3D §2.5: rotation, clipping, block input; plus flip and scaling). The previous sweep is first
// moved into the current frame (prev_to_current becomes identity), so every transform applies to both sweeps alike.
void augmentSample(DetectorSample* s, const TrainOptions& t, std::mt19937* rng);

// The grid of one training batch under the multi-scale schedule (LWD-3D eq. (4)): side 32 (base + n) cells, centred
// where the configured grid is centred; the configured grid when the schedule is off.
BevGeometry multiscaleGeometry(const BevGeometry& g, const TrainOptions& t, std::mt19937* rng);

}  // namespace ret3d
