// The optimisation side of IntraRM: batches of frames, the loss of Ret3D eq. (5) (focal classification +
// lambda_1 smooth-L1 location/size + lambda_2 smooth-L1 heading), AdamW steps, input normalisation from the training
// data, checkpoints. Data loading and the epoch loop live in the train layer (train/intra_trainer.h).
#pragma once

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "ret3d/core/detections.h"
#include "ret3d/relation/intra_rm.h"
#include "ret3d/relation/intra_rm_targets.h"

namespace ret3d {
namespace relation {

// One training frame: the detections (boxes + optional features) and their targets.
struct IntraRMFrame {
  Detections detections;
  std::vector<IntraRMTarget> targets;  // one per detection
};

struct IntraRMLoss {
  double total = 0, cls = 0, reg = 0, dir = 0;
  std::size_t positives = 0, nodes = 0;
};

class IntraRMLearner {
 public:
  IntraRMLearner(const IntraRMConfig& config, std::uint64_t seed);
  ~IntraRMLearner();

  // Sets the input normalisation (mean, std of every basic and detector feature) from training frames.
  void fitNormalisation(const std::vector<IntraRMFrame>& frames);
  // One AdamW step on the given frames (a mini-batch, augmented); returns the loss before the step.
  IntraRMLoss step(const std::vector<const IntraRMFrame*>& batch);
  // The mean loss over frames, without augmentation or gradients.
  IntraRMLoss evaluate(const std::vector<IntraRMFrame>& frames) const;

  // The module being trained (shares its weights with the learner).
  const IntraRM& model() const;
  // Copies the current weights (e.g. the best epoch) into a standalone module.
  IntraRM snapshot() const;
  void setTrainedOn(const std::string& text);

  // Checkpoint: weights, normalisation, optimiser state, and the caller's counters (written to DIR).
  void saveCheckpoint(const std::string& dir, int epoch, double best_val) const;
  // Returns false when DIR holds no checkpoint; throws when it holds a damaged or incompatible one.
  bool loadCheckpoint(const std::string& dir, int* epoch, double* best_val);

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace relation
}  // namespace ret3d
