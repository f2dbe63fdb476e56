// RelationLearner's state and its members shared by the IntraRM and InterRM learners (ret3d/relation/
// relation_learner.h), instantiated in intra_rm_learner.cpp and inter_rm_learner.cpp, which define before the
// instantiation, for their Impl and Sample types:
//   std::vector<Sample> augmented(Impl&, const std::vector<const Sample*>& batch);       // copies, augmented
//   std::pair<torch::Tensor, Loss> batchLoss(Impl&, const std::vector<const Sample*>& batch);
//   void fitInputNormalisation(Impl&, const std::vector<Sample>& samples);
//   Loss meanLoss(Impl&, const std::vector<Sample>& samples);                           // without gradients
//   bool sameNetwork(const Arch& a, const Arch& b);                                     // a checkpoint fits
// A training checkpoint is a folder DIR: DIR/model.pt (the module's model file), DIR/optimizer.pt, and
// DIR/state.yaml with the epochs done, the best validation loss so far and the augmentation RNG, written atomically.
// Errors name the module and the file.
#pragma once

#include <torch/torch.h>

#include <filesystem>
#include <random>
#include <string>

#include "model_archive.h"
#include "ret3d/relation/relation_learner.h"

namespace ret3d {
namespace relation {

// DIR/optimizer.pt and DIR/state.yaml (DIR created; DIR/model.pt is the caller's).
void writeLearnerCheckpoint(const std::string& dir, const torch::optim::Optimizer& optimizer, int epoch,
                            double best_val, const std::mt19937_64& rng);
// False when DIR/state.yaml does not exist; otherwise reads it. Throws std::runtime_error naming `module` and the
// file when it is unreadable.
bool readLearnerState(const std::string& dir, const std::string& module, int* epoch, double* best_val,
                      std::mt19937_64* rng);
// DIR/optimizer.pt into the optimiser; throws std::runtime_error naming `module` and the file when unreadable.
void readLearnerOptimizer(const std::string& dir, const std::string& module, torch::optim::Optimizer* optimizer);
// The saved network's parameters and buffers copied, by name, into the live one (same architecture).
void copyWeights(const torch::nn::Module& from, const torch::nn::Module& to);

template <class Module, class Sample, class Loss>
struct RelationLearner<Module, Sample, Loss>::Impl {
  Config config;
  Module model;
  std::unique_ptr<torch::optim::AdamW> optimizer;
  std::mt19937_64 rng;

  Impl(const Config& c, std::uint64_t seed) : config(c), model(c.model, seed), rng(seed) {
    model.impl().info.config = c;
    optimizer = std::make_unique<torch::optim::AdamW>(
        model.impl().net->parameters(), torch::optim::AdamWOptions(c.train.lr).weight_decay(c.train.weight_decay));
  }
  auto& net() { return model.impl().net; }
  static const std::string& what() { return Module::Impl::kFormat.what; }  // "IntraRM" in messages
};

template <class Module, class Sample, class Loss>
RelationLearner<Module, Sample, Loss>::RelationLearner(const Config& config, std::uint64_t seed)
    : impl_(std::make_unique<Impl>(config, seed)) {
  config.model.validate();
  config.train.validate();
}

template <class Module, class Sample, class Loss>
RelationLearner<Module, Sample, Loss>::~RelationLearner() = default;

template <class Module, class Sample, class Loss>
void RelationLearner<Module, Sample, Loss>::fitNormalisation(const std::vector<Sample>& samples) {
  fitInputNormalisation(*impl_, samples);
}

template <class Module, class Sample, class Loss>
Loss RelationLearner<Module, Sample, Loss>::step(const std::vector<const Sample*>& batch) {
  const std::vector<Sample> copies = augmented(*impl_, batch);
  std::vector<const Sample*> ptrs;
  for (const Sample& c : copies) ptrs.push_back(&c);
  impl_->net()->train();
  auto [total, loss] = batchLoss(*impl_, ptrs);
  impl_->optimizer->zero_grad();
  total.backward();
  torch::nn::utils::clip_grad_norm_(impl_->net()->parameters(), 10.0);
  impl_->optimizer->step();
  impl_->net()->eval();
  return loss;
}

template <class Module, class Sample, class Loss>
Loss RelationLearner<Module, Sample, Loss>::evaluate(const std::vector<Sample>& samples) const {
  torch::NoGradGuard no_grad;
  return meanLoss(*impl_, samples);
}

template <class Module, class Sample, class Loss>
const Module& RelationLearner<Module, Sample, Loss>::model() const {
  return impl_->model;
}

template <class Module, class Sample, class Loss>
Module RelationLearner<Module, Sample, Loss>::snapshot() const {
  Module copy(impl_->config.model);
  copy.impl().info = impl_->model.info();
  copyWeights(*impl_->model.impl().net, *copy.impl().net);
  return copy;
}

template <class Module, class Sample, class Loss>
void RelationLearner<Module, Sample, Loss>::setTrainedOn(const std::string& text) {
  impl_->model.impl().info.trained_on = text;
}

template <class Module, class Sample, class Loss>
void RelationLearner<Module, Sample, Loss>::saveCheckpoint(const std::string& dir, int epoch, double best_val) const {
  std::filesystem::create_directories(dir);
  impl_->model.save(dir + "/model.pt");
  writeLearnerCheckpoint(dir, *impl_->optimizer, epoch, best_val, impl_->rng);
}

template <class Module, class Sample, class Loss>
bool RelationLearner<Module, Sample, Loss>::loadCheckpoint(const std::string& dir, int* epoch, double* best_val) {
  if (!readLearnerState(dir, Impl::what(), epoch, best_val, &impl_->rng)) return false;
  typename Module::Impl saved;
  loadModule(dir + "/model.pt", &saved);
  if (!sameNetwork(saved.info.config.model, impl_->config.model))
    throw std::runtime_error(Impl::what() + " checkpoint " + dir + ": its network differs from the configuration (" +
                             toYaml(Config{saved.info.config.model, {}}) + ")");
  copyWeights(*saved.net, *impl_->net());
  impl_->model.impl().info.trained_on = saved.info.trained_on;
  readLearnerOptimizer(dir, Impl::what(), impl_->optimizer.get());
  return true;
}

}  // namespace relation
}  // namespace ret3d
