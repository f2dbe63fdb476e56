// IntraRM's network (Ret3D eqs. (1)-(4) and the head), its inputs, and the model file.
#include "intra_rm_network.h"

#include <cmath>
#include <stdexcept>

#include "ret3d/core/geometry.h"
#include "ret3d/relation/intra_rm_targets.h"

namespace ret3d {
namespace relation {

namespace nn = torch::nn;

IntraRMNetImpl::IntraRMNetImpl(const IntraRMArch& a) : arch(a) {
  arch.validate();
  const int64_t f = static_cast<int64_t>(arch.feature_dim);
  basic_mean = register_buffer("basic_mean", torch::zeros({kIntraBasicFeatures}));
  basic_std = register_buffer("basic_std", torch::ones({kIntraBasicFeatures}));
  feat_mean = register_buffer("feat_mean", torch::zeros({f}));
  feat_std = register_buffer("feat_std", torch::ones({f}));
  loc_scale = register_buffer("loc_scale", torch::ones({3}));
  box_scale = register_buffer("box_scale", torch::ones({4}));
  embed = register_module("embed", nn::Linear(kIntraBasicFeatures + f, arch.hidden));
  // H of eq. (2): EdgeConv's shared MLP on [x_j - x_i, x_i] (two layers; ReLU keeps the max of eq. (3) meaningful).
  for (int k = 0; k < arch.rounds; ++k) {
    edge_mlps.push_back(register_module("edge" + std::to_string(k),
                                        nn::Sequential(nn::Linear(2 * arch.hidden, arch.hidden), nn::ReLU(),
                                                       nn::Linear(arch.hidden, arch.hidden), nn::ReLU())));
  }
  // The head: a shared hidden layer over the concatenated rounds (eq. 4), then three linear layers for location,
  // heading + size, and class scores.
  head_trunk = register_module("head_trunk",
                               nn::Sequential(nn::Linear(arch.rounds * arch.hidden, arch.head_hidden), nn::ReLU()));
  head_loc = register_module("head_loc", nn::Linear(arch.head_hidden, 3));
  head_box = register_module("head_box", nn::Linear(arch.head_hidden, 4));
  head_cls = register_module("head_cls", nn::Linear(arch.head_hidden, kIntraNumClasses));
  score_gain = register_parameter("score_gain", torch::ones({kIntraNumClasses}));
  // The heads start at zero, so an untrained module returns the input boxes unchanged and ranks them as the base
  // detector did (its score through a sigmoid); training starts from the base detector rather than from noise.
  torch::NoGradGuard no_grad;
  for (auto* l : {&head_loc, &head_box, &head_cls}) {
    (*l)->weight.zero_();
    (*l)->bias.zero_();
  }
}

IntraRMOutput IntraRMNetImpl::forward(const torch::Tensor& basic, const torch::Tensor& feat,
                                      const torch::Tensor& source, const torch::Tensor& target) {
  const int64_t n = basic.size(0);
  torch::Tensor in = (basic - basic_mean) / basic_std;
  if (arch.feature_dim > 0) in = torch::cat({in, (feat - feat_mean) / feat_std}, 1);
  torch::Tensor x = embed->forward(in);  // eq. (1)
  std::vector<torch::Tensor> rounds;
  rounds.reserve(static_cast<std::size_t>(arch.rounds));
  for (int k = 0; k < arch.rounds; ++k) {
    const torch::Tensor xi = x.index_select(0, target);
    const torch::Tensor xj = x.index_select(0, source);
    const torch::Tensor e = edge_mlps[static_cast<std::size_t>(k)]->forward(torch::cat({xj - xi, xi}, 1));  // eq. (2)
    // eq. (3): channel-wise max over each node's neighbours (every node has its self-loop, so none is empty).
    x = torch::zeros({n, arch.hidden}, e.options())
            .scatter_reduce(0, target.unsqueeze(1).expand({e.size(0), e.size(1)}), e, "amax",
                            /*include_self=*/false);
    rounds.push_back(x);
  }
  const torch::Tensor h = head_trunk->forward(torch::cat(rounds, 1));  // eq. (4)
  const torch::Tensor score = in.slice(1, 10, 11);  // the normalised input score
  return {head_loc->forward(h) * loc_scale, head_box->forward(h) * box_scale,
          head_cls->forward(h) + score * score_gain};
}

void basicFeatures(const Box& b, float* o) {
  o[0] = static_cast<float>(b.x);
  o[1] = static_cast<float>(b.y);
  o[2] = static_cast<float>(b.z);
  o[3] = static_cast<float>(std::log(std::max(b.length, 1e-3)));
  o[4] = static_cast<float>(std::log(std::max(b.width, 1e-3)));
  o[5] = static_cast<float>(std::log(std::max(b.height, 1e-3)));
  o[6] = static_cast<float>(std::sin(b.yaw));
  o[7] = static_cast<float>(std::cos(b.yaw));
  o[8] = static_cast<float>(b.vx);
  o[9] = static_cast<float>(b.vy);
  o[10] = b.score;
  const int c = classIndex(b.label);
  for (int k = 0; k < 3; ++k) o[11 + k] = (c == k) ? 1.0f : 0.0f;
}

IntraRMInputs makeIntraRMInputs(const std::vector<const Detections*>& frames, const IntraRMArch& arch) {
  IntraRMInputs in;
  for (const Detections* d : frames) in.nodes += d->size();
  const int64_t n = static_cast<int64_t>(in.nodes);
  const int64_t f = static_cast<int64_t>(arch.feature_dim);
  in.basic = torch::empty({n, kIntraBasicFeatures});
  in.feat = torch::empty({n, f});
  float* pb = in.basic.data_ptr<float>();
  float* pf = in.feat.data_ptr<float>();
  std::vector<int64_t> src, dst;
  int64_t base = 0;
  for (const Detections* d : frames) {
    std::vector<Eigen::Vector2d> centres(d->size());
    for (std::size_t i = 0; i < d->size(); ++i) {
      const Box& b = d->boxes[i];
      centres[i] = {b.x, b.y};
      basicFeatures(b, pb + (base + static_cast<int64_t>(i)) * kIntraBasicFeatures);
      if (f > 0) std::copy(d->feature(i), d->feature(i) + f, pf + (base + static_cast<int64_t>(i)) * f);
    }
    const RadiusGraph g = buildRadiusGraph(centres, arch.radius, arch.use_edges);
    for (std::size_t k = 0; k < g.numEdges(); ++k) {
      src.push_back(g.source[k] + base);
      dst.push_back(g.target[k] + base);
    }
    base += static_cast<int64_t>(d->size());
  }
  in.source = torch::from_blob(src.data(), {static_cast<int64_t>(src.size())}, torch::kInt64).clone();
  in.target = torch::from_blob(dst.data(), {static_cast<int64_t>(dst.size())}, torch::kInt64).clone();
  return in;
}

torch::Tensor calibratedLogits(const torch::Tensor& cls, const IntraRMArch& arch) {
  const torch::Tensor scale = torch::tensor({static_cast<float>(arch.score_scale[0]),
                                             static_cast<float>(arch.score_scale[1]),
                                             static_cast<float>(arch.score_scale[2])});
  const torch::Tensor bias = torch::tensor({static_cast<float>(arch.score_bias[0]),
                                            static_cast<float>(arch.score_bias[1]),
                                            static_cast<float>(arch.score_bias[2])});
  return cls * scale + bias;
}

Detections applyIntraRMOutput(const Detections& input, const IntraRMOutput& out, const IntraRMArch& arch) {
  Detections result = input;
  if (input.empty()) return result;
  const bool refine_boxes = arch.refine_boxes;
  const torch::Tensor loc = out.loc.to(torch::kDouble).contiguous();
  const torch::Tensor box = out.box.to(torch::kDouble).contiguous();
  const torch::Tensor prob = torch::sigmoid(calibratedLogits(out.cls, arch)).contiguous();
  const double* pl = loc.data_ptr<double>();
  const double* pb = box.data_ptr<double>();
  const float* pc = prob.data_ptr<float>();
  for (std::size_t i = 0; i < result.size(); ++i) {
    Box& b = result.boxes[i];
    if (refine_boxes) {
      b.x += pl[3 * i];
      b.y += pl[3 * i + 1];
      b.z += pl[3 * i + 2];
      b.yaw = wrapAngle(b.yaw + pb[4 * i]);
      b.length *= std::exp(pb[4 * i + 1]);
      b.width *= std::exp(pb[4 * i + 2]);
      b.height *= std::exp(pb[4 * i + 3]);
    }
    const int c = classIndex(b.label);
    if (c >= 0) {
      b.score = pc[3 * i + c];
    } else {
      b.score = std::max({pc[3 * i], pc[3 * i + 1], pc[3 * i + 2]});
    }
  }
  return result;
}

// ---- model file ---------------------------------------------------------------------------------------------------

template class RelationModule<IntraRMImpl, IntraRMConfig>;

IntraRMModelInfo readIntraRMModelInfo(const std::string& path) { return readModuleInfo<IntraRMImpl>(path); }

}  // namespace relation
}  // namespace ret3d
