// IntraRM's torch network and the model file format; private to src/relation (and the trainer), so the public
// headers stay free of torch.
#pragma once

#include <string>
#include <vector>

#include <torch/torch.h>

#include "model_archive.h"
#include "ret3d/core/detections.h"
#include "ret3d/relation/intra_rm.h"
#include "ret3d/relation/radius_graph.h"

namespace ret3d {
namespace relation {

// Output channels: centre residual (3), heading residual (1) + log-size residual (3), class logits (3).
inline constexpr int kIntraNumClasses = 3;

struct IntraRMOutput {
  torch::Tensor loc;  // n x 3: centre residual, metres
  torch::Tensor box;  // n x 4: heading residual (rad), log-size residuals (l, w, h)
  torch::Tensor cls;  // n x 3: class logits (Car, Pedestrian, Cyclist)
};

class IntraRMNetImpl : public torch::nn::Module {
 public:
  explicit IntraRMNetImpl(const IntraRMArch& arch);
  // basic: n x 14 raw basic features; feat: n x feature_dim (or undefined when feature_dim 0); source/target: the
  // graph's edges (int64). Normalises, embeds (eq. 1), runs `rounds` EdgeConv rounds (eqs. 2-3), concatenates the
  // rounds (eq. 4) and applies the head.
  IntraRMOutput forward(const torch::Tensor& basic, const torch::Tensor& feat, const torch::Tensor& source,
                        const torch::Tensor& target);

  IntraRMArch arch;
  // Input normalisation (buffers, saved with the weights): x_norm = (x - mean) / std.
  torch::Tensor basic_mean, basic_std, feat_mean, feat_std;
  // Scale of the regression outputs (centre x y z, heading, log size l w h): the spread of the residuals in the
  // training data. The heads predict residuals in these units, so the loss sees errors of order one rather than
  // centimetres (a well-placed detector's residuals are a few centimetres, too small for smooth-L1 to learn from).
  torch::Tensor loc_scale, box_scale;
  torch::nn::Linear embed{nullptr};                 // W^x of eq. (1)
  std::vector<torch::nn::Sequential> edge_mlps;     // H of eq. (2), one per round
  torch::nn::Sequential head_trunk{nullptr};
  torch::nn::Linear head_loc{nullptr}, head_box{nullptr}, head_cls{nullptr};
  // Per-class gain on the normalised input score, added to the class logits: the classification is a residual on
  // the base detector's own ranking, as the box outputs are residuals on its boxes.
  torch::Tensor score_gain;
};
TORCH_MODULE(IntraRMNet);

struct IntraRMImpl : ModuleState<IntraRMNet, IntraRMConfig> {
  inline static const ModelFormat kFormat{"IntraRM", "ret3d-intra-rm", 1, kIntraBasicFeatures, ArchiveLayout::Nested};
  static constexpr auto parseConfig = &parseIntraRMConfig;
};

// The inputs of one batch of frames as tensors (frames laid side by side; edges never cross frames).
struct IntraRMInputs {
  torch::Tensor basic, feat, source, target;
  std::size_t nodes = 0;
};
IntraRMInputs makeIntraRMInputs(const std::vector<const Detections*>& frames, const IntraRMArch& arch);

// Applies the predicted scores and (when refine_boxes) residuals to the input boxes.
Detections applyIntraRMOutput(const Detections& input, const IntraRMOutput& out, const IntraRMArch& arch);
// The class logits with the model's score calibration applied (IntraRMArch::score_scale, score_bias), N x 3.
torch::Tensor calibratedLogits(const torch::Tensor& cls, const IntraRMArch& arch);

}  // namespace relation
}  // namespace ret3d
