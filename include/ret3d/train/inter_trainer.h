// InterRM (Ret3D §3.3) training: sequences built by running the tracker over another detector's boxes with the real
// ego poses (optionally IntraRM first), through the same TrackHistories the pipeline refines from
// (pipeline/track_histories.h), and the epoch loop with checkpoints.
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "ret3d/io/detection_cache.h"
#include "ret3d/relation/inter_rm.h"
#include "ret3d/relation/inter_rm_learner.h"
#include "ret3d/tracking/tracker_options.h"

namespace ret3d {
namespace train {

struct InterDataOptions {
  std::string data_dir;        // KITTI tracking root (label_02, calib, pose or oxts)
  std::string detections_dir;  // detector outputs (KITTI tracking result files or the per-class CSV layout)
  const io::SequenceDetections* detector_outputs = nullptr;  // instead: this package's detector's (detector_outputs.h)
  std::vector<std::string> sequences;  // empty = every sequence with labels
  std::string intra_model;     // optional IntraRM model run on each frame before tracking
  TrackerOptions tracker;
  double frame_period = 0.1;   // s between frames (KITTI: 10 Hz)
};

// One sample per tracked box whose class-aware best BEV IoU with a ground-truth box reaches reg_min_iou of its class
// (the assignment IntraRM uses); the target is that ground-truth box. Throws std::runtime_error naming what is
// missing (labels, poses, a detection layout without sequences).
std::vector<relation::InterRMSample> loadInterSamples(const InterDataOptions& data,
                                                      const relation::InterRMTrainConfig& config);

struct InterTrainOptions {
  relation::InterRMConfig config;
  std::string out_path;        // the model file (best validation epoch, or the last one without validation)
  std::string checkpoint_dir;  // default: out_path + ".ckpt"
  bool resume = false;
  std::string trained_on;
  bool progress = true;
};

struct InterTrainReport {
  int epochs_run = 0, best_epoch = -1;
  double first_train_loss = 0, last_train_loss = 0, best_val_loss = 0;
  double initial_val_loss = 0;  // validation loss of the untrained (identity) module = the input boxes' error
  std::vector<double> val_losses;
  double seconds = 0;
  std::size_t train_sequences = 0, val_sequences = 0;
};

InterTrainReport trainInterRM(const std::vector<relation::InterRMSample>& train,
                              const std::vector<relation::InterRMSample>& val, const InterTrainOptions& options);

}  // namespace train
}  // namespace ret3d
