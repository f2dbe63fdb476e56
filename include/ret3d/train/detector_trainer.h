// The base detector's training loop (`ret3d train detector`): k-means anchors, AdamW with warm-up and cosine decay,
// fixed seeds, augmentation and the multi-scale schedule, checkpoints every few minutes and resume, a progress bar
// with the losses. The model trained is the very DetectorModel the Detector runs.
#pragma once

#include <functional>
#include <string>
#include <vector>

#include "ret3d/detector/detector_options.h"
#include "ret3d/train/detector_dataset.h"

namespace ret3d {

struct DetectorTrainJob {
  std::vector<std::string> data_dirs;  // KITTI folders (tracking or object layout), used together
  std::vector<double> data_weights;    // per folder (or one for all; empty = 1): frames drawn per epoch per frame
  std::vector<LabelCover> label_cover;  // per folder (or one for all; empty = Auto): where the labels exist
  std::string out_model;      // final model file; checkpoints beside it (<out>.ckpt, <out>.ckpt.optim)
  DetectorOptions options;
  std::string config_text;    // the YAML the options came from, stored in the model file
  bool resume = false;
  std::string init_model;     // when set (and not resuming): start from this model's weights and anchors, with a
                              // fresh optimiser and learning-rate schedule (a second, fine-tuning stage)
  bool init_other_cells = false;  // init_model may have another cell size (DetectorModel::extend)
  bool progress = true;       // draw the progress bar
};

struct DetectorTrainResult {
  int steps = 0;              // optimiser steps in total (including before a resume)
  double seconds = 0;         // wall time of this run
  double last_loss = 0;       // mean total loss over the last epoch
};

DetectorTrainResult trainDetector(const DetectorTrainJob& job);

}  // namespace ret3d
