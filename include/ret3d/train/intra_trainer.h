// Training IntraRM on another detector's boxes (KITTI tracking or object layout, detections in any layout of
// io/detections.h): data loading with ground-truth assignment, the epoch loop with validation, checkpoints, resume.
#pragma once

#include <string>
#include <vector>

#include "ret3d/io/detection_cache.h"
#include "ret3d/relation/intra_rm_learner.h"

namespace ret3d {
namespace train {

struct IntraDataOptions {
  std::string data_dir;        // KITTI tracking root (training/label_02, calib) or object root (label_2, calib)
  std::string detections_dir;  // detector outputs: KITTI object/tracking result files or the per-class CSV layout
  std::vector<std::string> sequences;  // tracking sequences to use; empty = every sequence with labels
};

// Frames with at least one detection, in LiDAR coordinates, with their targets (relation/intra_rm_targets.h).
// Van / Person_sitting ground truth and DontCare regions become "ignore" as the KITTI benchmark treats them.
std::vector<relation::IntraRMFrame> loadIntraFrames(const IntraDataOptions& data,
                                                    const relation::IntraRMTrainConfig& config);

// Frames from this package's detector (boxes with features, train/detector_outputs.h) on a labelled tracking dataset.
std::vector<relation::IntraRMFrame> loadIntraFrames(const std::string& data_dir, const io::SequenceDetections& detections,
                                                    const relation::IntraRMTrainConfig& config);

struct IntraTrainOptions {
  relation::IntraRMConfig config;
  std::string out_path;        // the model file written (best validation epoch, or the last one without validation)
  std::string checkpoint_dir;  // default: out_path + ".ckpt"
  bool resume = false;         // continue from checkpoint_dir when it holds a checkpoint
  std::string trained_on;      // stored in the model's metadata (data, command)
  bool progress = true;
};

struct IntraTrainReport {
  int epochs_run = 0, best_epoch = -1;
  double first_train_loss = 0, last_train_loss = 0, best_val_loss = 0;
  std::vector<double> val_losses;  // per epoch (empty without validation frames)
  double seconds = 0;
  std::size_t train_frames = 0, val_frames = 0, train_boxes = 0;
};

IntraTrainReport trainIntraRM(const std::vector<relation::IntraRMFrame>& train,
                              const std::vector<relation::IntraRMFrame>& val, const IntraTrainOptions& options);

}  // namespace train
}  // namespace ret3d
