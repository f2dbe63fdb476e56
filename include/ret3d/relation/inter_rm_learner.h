// The optimisation side of InterRM (Ret3D §3.3): batches of tracked sequences, the smooth-L1 regression loss of the
// current box's residuals (L_inter), AdamW steps, input normalisation from the training data, checkpoints. Building
// the sequences (tracker over detections) and the epoch loop live in the train layer (train/inter_trainer.h).
#pragma once

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "ret3d/relation/inter_rm.h"

namespace ret3d {
namespace relation {

// One training sequence and the ground truth its current box (sequence.boxes[0]) is regressed to.
struct InterRMSample {
  InterRMSequence sequence;
  Box target;  // same frame as the sequence (the current sensor frame)
};

struct InterRMLoss {
  double total = 0, loc = 0, size = 0, yaw = 0;  // mean smooth-L1 per sequence (loc: dx dy dz, size: 3 logs, yaw)
  std::size_t sequences = 0;
};

// The regression target of a sample: residuals of target w.r.t. sequence.boxes[0], in the current box's frame
// (dx, dy, dz, log l, log w, log h ratios, heading wrapped to [-pi/2, pi/2)), as the network predicts them.
std::array<float, 7> interResiduals(const Box& current, const Box& target);

class InterRMLearner {
 public:
  InterRMLearner(const InterRMConfig& config, std::uint64_t seed);
  ~InterRMLearner();

  // Sets the input normalisation (mean, std of every feature except heading sin/cos and class one-hot).
  void fitNormalisation(const std::vector<InterRMSample>& samples);
  // One AdamW step on a mini-batch (augmented when configured); returns the loss before the step.
  InterRMLoss step(const std::vector<const InterRMSample*>& batch);
  // The mean loss over samples, without augmentation or gradients.
  InterRMLoss evaluate(const std::vector<InterRMSample>& samples) const;

  const InterRM& model() const;
  void setTrainedOn(const std::string& text);

  // Checkpoint: model file, optimiser state and the caller's counters (written to DIR).
  void saveCheckpoint(const std::string& dir, int epoch, double best_val) const;
  // Returns false when DIR holds no checkpoint; throws when it holds a damaged or incompatible one.
  bool loadCheckpoint(const std::string& dir, int* epoch, double* best_val);

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace relation
}  // namespace ret3d
