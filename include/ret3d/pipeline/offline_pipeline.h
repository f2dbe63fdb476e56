// The ret3d pipeline run offline, frame by frame, as the nodelets run it online: base detector (on point clouds),
// IntraRM, tracker, InterRM. Shared by `ret3d detect` (writes KITTI results), `ret3d bench` (times each stage),
// `ret3d autolabel` and `ret3d draw`. No ROS here: what only the command line knows (the package folder) comes in the
// config.
#pragma once

#include <map>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Geometry>

#include "ret3d/core/detections.h"
#include "ret3d/core/types.h"
#include "ret3d/detector/detector.h"
#include "ret3d/pipeline/track_refiner.h"
#include "ret3d/relation/inter_rm.h"
#include "ret3d/relation/intra_rm.h"

namespace ret3d {
namespace pipeline {

struct PipelineConfig {
  std::vector<std::string> stages;  // in order, from: base, intra, track, inter ("inter" implies the tracker)
  std::string models;               // folder with detector.pt, intra_rm.pt, inter_rm.pt (the defaults below)
  std::string detector_model, intra_model, inter_model;  // explicit files win over --models
  std::string detector_config;      // YAML for the detector's inference options (default: those it was trained with)
  std::string tracker_config;       // tracker YAML; empty: defaultTrackerConfig(stages, package_dir)
  std::string package_dir;          // the ret3d package folder; only read when usesPackageDir(config)
  double score_threshold = -1;      // >= 0: overrides the detector's inference.score_threshold
  // The nodelets' parameter file's detector threshold (config/ret3d.yaml, ret3d_detector/score_threshold), read by the
  // caller when usesPackageDir(config); applies when the pipeline tracks (pipeline/score_threshold.h). nullopt: none.
  std::optional<double> params_score_threshold;
  std::vector<double> grid_extent;  // non-empty: overrides inference.grid_extent [x_min, x_max, y_min, y_max]
  int threads = 2;
};

// True when the pipeline needs config.package_dir (and params_score_threshold): the base stage tracks, without
// --tracker-config (the nodelets' tracker config) or without --score-threshold (the threshold the nodelets' detector
// feeds their tracker from; pipeline/score_threshold.h).
bool usesPackageDir(const PipelineConfig& config);

// Parses "base,intra,track" (or "none"): throws naming an unknown stage or a misplaced one.
std::vector<std::string> parseStages(const std::string& list);

// Per-stage wall times of every frame run, milliseconds. Stage names: bev, network, decode, nms (the base
// detector's parts), intra, track, inter; "total" is their sum per frame.
class StageTimes {
 public:
  void add(const std::string& stage, double ms) { ms_[stage].push_back(ms); }
  const std::map<std::string, std::vector<double>>& all() const { return ms_; }
  void clear() { ms_.clear(); }

 private:
  std::map<std::string, std::vector<double>> ms_;
};

class OfflinePipeline {
 public:
  // Loads every model the stages need; throws saying which file is missing or wrong.
  explicit OfflinePipeline(const PipelineConfig& config);
  ~OfflinePipeline();

  bool hasBase() const { return static_cast<bool>(detector_); }
  bool tracks() const { return static_cast<bool>(tracking_); }
  // Boxes kept per track (0 without tracking): InterRM's history length, or the tracker's without InterRM.
  int historyLength() const { return history_length_; }
  const Detector* detector() const { return detector_.get(); }
  // Length of the detector features IntraRM expects with each box (0: none, or no IntraRM stage).
  std::size_t intraFeatureDim() const;
  std::string describe() const;  // the stages and the model files, one line

  // A new sequence: the tracker forgets its tracks.
  void reset();
  // One frame. With the base stage, detections come from `current` (and the previous sweep, moved by
  // prev_to_current); without it, `input` holds another detector's boxes. `stamp` (s) and `sensor_to_fixed` (the
  // ego pose) feed the tracker.
  Detections run(const PointCloud* current, const PointCloud* previous, const Eigen::Isometry3d& prev_to_current,
                 Detections input, double stamp, const Eigen::Isometry3d& sensor_to_fixed);
  const StageTimes& times() const { return times_; }
  void clearTimes() { times_.clear(); }

 private:
  std::vector<std::string> stages_;
  std::string description_;
  std::unique_ptr<Detector> detector_;
  std::unique_ptr<relation::IntraRM> intra_;
  std::unique_ptr<relation::InterRM> inter_;
  int history_length_ = 0;
  std::unique_ptr<TrackRefiner> tracking_;
  StageTimes times_;
};

}  // namespace pipeline
}  // namespace ret3d
