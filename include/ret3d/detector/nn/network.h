// The LWD-3D backbone as libtorch modules, used unchanged by training (src/train) and inference (Detector).
// Torch-level header: included only by .cpp files of the detector and train layers (the public detector headers
// stay free of libtorch).
#pragma once

#include <cstdint>
#include <map>
#include <utility>
#include <vector>

#include <torch/torch.h>

#include "ret3d/detector/detector_options.h"

namespace ret3d {
namespace nn {

// Conv (k x k) + BatchNorm + ReLU. In eval mode the BatchNorm is folded into the convolution (its weights scaled, a
// bias added): one pass over the activations instead of two. The folded copy is made again whenever a weight or a
// running statistic has changed since (the tensors' version counters), so a model shared with training stays right.
struct ConvBnReluImpl : torch::nn::Module {
  ConvBnReluImpl(int in, int out, int kernel, int stride, int groups = 1, bool relu = true);
  torch::Tensor forward(const torch::Tensor& x);
  torch::nn::Conv2d conv{nullptr};
  torch::nn::BatchNorm2d bn{nullptr};
  bool relu;

 private:
  void fold();
  int stride_, padding_, groups_;
  torch::Tensor folded_weight_, folded_bias_;
  std::vector<std::pair<const void*, std::uint32_t>> folded_from_;  // (data, version) of the tensors folded
};
TORCH_MODULE(ConvBnRelu);

// Depthwise-separable convolution (LWD-3D Fig. 4, MobileNet): 3x3 depthwise, then 1x1 pointwise; a residual
// connection when the shape is kept.
struct DepthwiseSeparableImpl : torch::nn::Module {
  DepthwiseSeparableImpl(int in, int out, int stride);
  torch::Tensor forward(const torch::Tensor& x);
  ConvBnRelu depthwise{nullptr}, pointwise{nullptr};
  bool residual;
};
TORCH_MODULE(DepthwiseSeparable);

// One transformer block over the cells of a feature map (LWD-3D §2.3): pre-norm multi-head self-attention and an
// MLP, both residual. A depthwise conv before it re-encodes position (the "spatial order" the paper keeps), so the
// block works at any grid size, as the multi-scale training needs.
struct TransformerBlockImpl : torch::nn::Module {
  TransformerBlockImpl(int channels, int heads);
  torch::Tensor forward(const torch::Tensor& x);  // N x C x H x W -> same
  torch::nn::Conv2d position{nullptr};
  torch::nn::LayerNorm norm1{nullptr}, norm2{nullptr};
  torch::nn::MultiheadAttention attention{nullptr};
  torch::nn::Linear fc1{nullptr}, fc2{nullptr};
};
TORCH_MODULE(TransformerBlock);

struct NetworkOutput {
  std::map<int, torch::Tensor> head;  // stride -> raw head map (N x channels x H/stride x W/stride)
  torch::Tensor features;             // the BEV feature map B (finest head stride), N x decoder_channels x h x w
};

// Stem, depthwise-separable stages, transformer, decoder, and one prediction branch per head stride.
struct LwdNetworkImpl : torch::nn::Module {
  // head_channels_per_stride: the output channels of the head at each stride (they depend on the head type).
  LwdNetworkImpl(const NetworkOptions& options, int in_channels, const std::map<int, int>& head_channels_per_stride);
  NetworkOutput forward(const torch::Tensor& bev);
  // Initialises the bias of the first `count` channels of the head at `stride` every `period` channels, among its
  // first `end` channels (0 = all) (focal-loss prior, RetinaNet: -log((1 - p) / p)).
  void initClassificationBias(int stride, int first, int count, int period, double prior, int end = 0);

  NetworkOptions options;
  ConvBnRelu stem{nullptr};
  std::vector<torch::nn::Sequential> stages;
  torch::nn::Sequential transformer{nullptr};
  std::map<int, torch::nn::Conv2d> laterals;           // stride -> 1x1 conv to decoder channels
  std::map<int, DepthwiseSeparable> fuse;               // stride -> block after upsample + lateral
  std::map<int, torch::nn::Sequential> heads;           // stride -> prediction branch
};
TORCH_MODULE(LwdNetwork);

// Parameter count of a module.
std::int64_t parameterCount(const torch::nn::Module& m);

}  // namespace nn
}  // namespace ret3d
