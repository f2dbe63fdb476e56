// The ret3d pipeline run offline, frame by frame, as the nodelets run it online: base detector (on point clouds),
// IntraRM, tracker, InterRM. Shared by `ret3d detect` (writes KITTI results) and `ret3d bench` (times each stage).
#pragma once

#include <map>
#include <memory>
#include <string>
#include <vector>

#include <Eigen/Geometry>

#include "ret3d/core/detections.h"
#include "ret3d/core/types.h"
#include "ret3d/detector/detector.h"
#include "ret3d/relation/inter_rm.h"
#include "ret3d/relation/intra_rm.h"
#include "ret3d/train/inter_trainer.h"

namespace CLI {
class App;
}

namespace ret3d {
namespace tools {

struct PipelineConfig {
  std::vector<std::string> stages;  // in order, from: base, intra, track, inter ("inter" implies the tracker)
  std::string models;               // folder with detector.pt, intra_rm.pt, inter_rm.pt (the defaults below)
  std::string detector_model, intra_model, inter_model;  // explicit files win over --models
  std::string detector_config;      // YAML for the detector's inference options (default: those it was trained with)
  std::string tracker_config;       // tracker YAML; empty: defaultTrackerConfig(stages) (tools/tracker_default.h)
  double score_threshold = -1;      // >= 0: overrides the detector's inference.score_threshold
  std::vector<double> grid_extent;  // non-empty: overrides inference.grid_extent [x_min, x_max, y_min, y_max]
  int threads = 2;
};

// The --grid-extent option of the commands that run the detector (x_min,x_max,y_min,y_max in metres).
void addGridExtentOption(CLI::App& app, std::vector<double>* extent);

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
  int historyLength() const { return history_length_; }  // boxes kept per track (0 without tracking)
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
  std::unique_ptr<train::TrackingRefiner> tracking_;
  StageTimes times_;
};

}  // namespace tools
}  // namespace ret3d
