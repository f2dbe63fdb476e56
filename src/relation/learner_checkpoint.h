// What the IntraRM and InterRM learners' training checkpoints share (a folder DIR): DIR/model.pt (written by the
// module's own save), DIR/optimizer.pt, and DIR/state.yaml with the epochs done, the best validation loss so far and
// the augmentation RNG, written atomically. Errors name the module and the file.
#pragma once

#include <torch/torch.h>

#include <random>
#include <string>

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

}  // namespace relation
}  // namespace ret3d
