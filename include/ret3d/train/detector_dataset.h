// Training samples for the base detector from KITTI folders (real or simulated). Tracking layout: two consecutive
// sweeps, the ego motion between them (LiDAR poses), and the labelled boxes with velocities from their track ids.
// Object layout: one sweep and its boxes, without a previous sweep or velocity targets.
#pragma once

#include <optional>
#include <random>
#include <string>
#include <vector>

#include <Eigen/Geometry>

#include "ret3d/core/geometry.h"
#include "ret3d/core/types.h"
#include "ret3d/detector/detector_options.h"
#include "ret3d/io/kitti.h"

namespace ret3d {

struct CoverEvidence;  // what a set's labels show about their cover (detector_dataset.cpp)

// Where a set's labels exist. Real KITTI labels cover only camera 2's view; the simulator labels all around.
enum class LabelCover { Auto, All, Camera };
LabelCover labelCoverFromName(const std::string& name);  // "auto", "all", "camera"; throws naming the value
std::string labelCoverName(LabelCover c);

// One training set: a KITTI folder (tracking or object layout, detected), how often its frames are drawn, and where
// its labels exist.
struct DetectorDataSource {
  std::string root;
  double weight = 1.0;  // each frame appears `weight` times per epoch on average
  LabelCover cover = LabelCover::Auto;  // Auto: Camera when every object label has a 2D box in image 2, else All
};

struct DetectorSample {
  std::string id;                  // "SSSS/FFFFFF"
  PointCloud current;
  PointCloud previous;             // empty for the first frame of a sequence
  bool has_previous = false;
  Eigen::Isometry3d prev_to_current = Eigen::Isometry3d::Identity();
  std::vector<Box> boxes;          // the model's classes, LiDAR frame, velocity in m/s
  std::vector<bool> velocity_valid;
  std::vector<Box> ignore;         // DontCare, and the classes KITTI ignores for ours (Van for Car, ...)
  std::vector<BevWedge> ignore_regions;  // behind DontCare image boxes (KITTI gives them no 3D box)
  std::optional<BevWedge> labelled_view;  // set when the labels cover only this wedge (camera 2's view)
};

class DetectorDataset {
 public:
  // Indexes every labelled frame with a scan (labels are read now; scans on load()) of one or more folders, e.g.
  // urban and highway simulations and a real KITTI object folder. Each folder's layout is detected (tracking:
  // label_02/ or velodyne/SSSS/; object: label_2/); throws when a folder is neither or nothing is labelled.
  DetectorDataset(const std::vector<DetectorDataSource>& sources, const ModelConfig& model, int max_frames = 0);
  DetectorDataset(const std::vector<std::string>& roots, const ModelConfig& model, int max_frames = 0);
  DetectorDataset(const std::string& root, const ModelConfig& model, int max_frames = 0)
      : DetectorDataset(std::vector<std::string>{root}, model, max_frames) {}
  std::size_t size() const { return frames_.size(); }
  // The sets: their sources (cover resolved: never Auto), layouts, and which set each frame belongs to.
  const std::vector<DetectorDataSource>& sources() const { return sources_; }
  const std::string& layout(std::size_t set) const { return layouts_.at(set); }  // "tracking" or "object"
  std::size_t setOf(std::size_t i) const { return seqs_[frames_.at(i).seq].set; }
  std::size_t setSize(std::size_t set) const;
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
    std::size_t set = 0;                         // index into sources_
    bool object = false;                         // an object-layout frame (name = its file stem)
    std::string root;                            // the dataset folder it belongs to
    std::string name;
    kitti::Calibration calib;
    std::optional<BevWedge> view;                // the labelled field of view (camera-cover sets)
    std::vector<std::vector<BevWedge>> dont_care;  // per frame index: the DontCare regions
    std::vector<Eigen::Isometry3d> poses;       // T_velo0_velo_t, empty when absent
    std::vector<std::vector<Box>> boxes;         // per frame index: every labelled box (class Unknown for others)
    std::vector<std::vector<std::string>> types; // the KITTI type of each box
    std::vector<std::vector<bool>> velocity_valid;  // per box: its velocity came from its track
  };
  void addTracking(std::size_t set, CoverEvidence* evidence);
  void addObject(std::size_t set, CoverEvidence* evidence);
  Eigen::Isometry3d motion(const Sequence& s, int from, int to) const;  // T_to_from
  ModelConfig model_;
  std::vector<DetectorDataSource> sources_;
  std::vector<std::string> layouts_;
  std::vector<Sequence> seqs_;
  std::vector<Frame> frames_;
};

// The frames of one epoch, shuffled: each frame of set k appears floor(w_k) times plus once more with probability
// frac(w_k) (w_k = sources()[k].weight). Depends only on (seed, epoch), so a resumed run draws the same epoch; with
// every weight 1 it is the plain shuffle of all frames.
std::vector<std::size_t> epochOrder(const DetectorDataset& data, unsigned seed, int epoch);

// Augmentation (LWD-3D §2.5: rotation, clipping, block input; plus flip and scaling). The previous sweep is first
// moved into the current frame (prev_to_current becomes identity), so every transform applies to both sweeps alike.
// Clipping and block input are drawn over `grid` (the model's configured grid, not a batch's multi-scale crop).
void augmentSample(DetectorSample* s, const TrainOptions& t, const BevGeometry& grid, std::mt19937* rng);

// The grid of one training batch under the multi-scale schedule (LWD-3D eq. (4)): side 32 (base + n) cells, centred
// where the configured grid is centred; the configured grid when the schedule is off.
BevGeometry multiscaleGeometry(const BevGeometry& g, const TrainOptions& t, std::mt19937* rng);

}  // namespace ret3d
