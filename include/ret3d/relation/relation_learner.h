// What the IntraRM and InterRM learners share: one class over the module being trained (Module: IntraRM or InterRM),
// with its AdamW optimiser (the paper's), the augmentation RNG, the optimisation step and the checkpoints. Sample is
// one training example, Loss the loss terms (.total). What differs (the loss, the augmentation, the input
// normalisation, the validation batches) is in src/relation/intra_rm_learner.cpp and inter_rm_learner.cpp, which
// instantiate the class; data loading and the epoch loop live in the train layer.
#pragma once

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

namespace ret3d {
namespace relation {

template <class Module, class Sample, class Loss>
class RelationLearner {
 public:
  using Config = typename Module::Config;

  RelationLearner(const Config& config, std::uint64_t seed);
  ~RelationLearner();

  // Sets the input normalisation (mean, std of the input features) from training samples.
  void fitNormalisation(const std::vector<Sample>& samples);
  // One AdamW step on a mini-batch (augmented as configured); returns the loss before the step.
  Loss step(const std::vector<const Sample*>& batch);
  // The mean loss over samples, without augmentation or gradients.
  Loss evaluate(const std::vector<Sample>& samples) const;

  // The module being trained (shares its weights with the learner).
  const Module& model() const;
  // Copies the current weights (e.g. the best epoch) into a standalone module.
  Module snapshot() const;
  void setTrainedOn(const std::string& text);

  // Checkpoint: model file, optimiser state, augmentation RNG and the caller's counters (written to DIR).
  void saveCheckpoint(const std::string& dir, int epoch, double best_val) const;
  // Returns false when DIR holds no checkpoint; throws when it holds a damaged or incompatible one.
  bool loadCheckpoint(const std::string& dir, int* epoch, double* best_val);

  struct Impl;  // src/relation/learner_checkpoint.h: torch types

 private:
  std::unique_ptr<Impl> impl_;
};

}  // namespace relation
}  // namespace ret3d
