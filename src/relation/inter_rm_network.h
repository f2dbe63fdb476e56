// InterRM's torch network and model file format; private to src/relation (and the learner), so the public headers
// stay free of torch.
#pragma once

#include <string>
#include <vector>

#include <torch/torch.h>

#include "model_archive.h"
#include "ret3d/relation/inter_rm.h"

namespace ret3d {
namespace relation {

// Outputs: centre residual (3, current box frame), log-size residual (3), heading residual (1).
inline constexpr int kInterOutputs = 7;

// A batch of sequences as tensors, newest entry first, padded to the longest (B x L).
struct InterRMInputs {
  torch::Tensor features;  // B x L x kInterBasicFeatures, raw (zeros where padded)
  torch::Tensor padding;   // B x L bool, true = padding
  torch::Tensor dt;        // B x L, seconds
  torch::Tensor position;  // B x L x 2, sensor-frame x, y (spatial encoding)
};
// Sequences longer than max_history keep their newest max_history entries. Throws std::invalid_argument for an empty
// sequence, a dt of another length, or a non-finite field.
InterRMInputs makeInterRMInputs(const std::vector<const InterRMSequence*>& sequences, int max_history);

class InterRMNetImpl : public torch::nn::Module {
 public:
  explicit InterRMNetImpl(const InterRMArch& arch);
  // B x kInterOutputs residuals of each sequence's current box (entry 0).
  torch::Tensor forward(const InterRMInputs& in);

  InterRMArch arch;
  torch::Tensor feat_mean, feat_std;  // input normalisation (buffers): x_norm = (x - mean) / std
  torch::nn::Linear encode{nullptr};  // W^e, eq. (6)
  torch::nn::Linear wq{nullptr}, wk{nullptr}, wv{nullptr}, wo{nullptr};  // eq. (7) and the heads' output projection
  torch::nn::Linear ffn1{nullptr}, ffn2{nullptr};                        // FFN of eq. (9), expansion ffn_expansion
  torch::nn::Linear head{nullptr};                                       // the regression layer

 private:
  torch::Tensor positionalEncoding(const InterRMInputs& in) const;  // B x L x C, undefined for Implicit
};
TORCH_MODULE(InterRMNet);

struct InterRMImpl : ModuleState<InterRMNet, InterRMConfig> {
  inline static const ModelFormat kFormat{"InterRM", "ret3d-inter-rm", 1, kInterBasicFeatures, ArchiveLayout::Flat};
  static constexpr auto parseConfig = &parseInterRMConfig;
};

// Applies predicted residuals (B x 7) to each sequence's current box.
std::vector<Box> applyInterRMOutput(const std::vector<const InterRMSequence*>& sequences, const torch::Tensor& out,
                                    bool apply_size);

}  // namespace relation
}  // namespace ret3d
