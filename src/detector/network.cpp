#include "ret3d/detector/nn/network.h"

#include <cmath>

namespace ret3d {
namespace nn {

namespace F = torch::nn::functional;

ConvBnReluImpl::ConvBnReluImpl(int in, int out, int kernel, int stride, int groups, bool relu_)
    : relu(relu_), stride_(stride), padding_(kernel / 2), groups_(groups) {
  conv = register_module("conv", torch::nn::Conv2d(torch::nn::Conv2dOptions(in, out, kernel)
                                                       .stride(stride)
                                                       .padding(kernel / 2)
                                                       .groups(groups)
                                                       .bias(false)));
  bn = register_module("bn", torch::nn::BatchNorm2d(out));
}

void ConvBnReluImpl::fold() {
  const std::vector<torch::Tensor> from = {conv->weight, bn->weight, bn->bias, bn->running_mean, bn->running_var};
  std::vector<std::pair<const void*, std::uint32_t>> now;
  for (const auto& t : from) now.emplace_back(t.data_ptr(), t._version());
  if (now == folded_from_) return;
  torch::NoGradGuard no_grad;
  const auto scale = bn->weight / torch::sqrt(bn->running_var + bn->options.eps());
  folded_weight_ = conv->weight * scale.reshape({-1, 1, 1, 1});
  folded_bias_ = bn->bias - bn->running_mean * scale;
  folded_from_ = std::move(now);
}

torch::Tensor ConvBnReluImpl::forward(const torch::Tensor& x) {
  torch::Tensor y;
  if (is_training()) {
    y = bn(conv(x));
  } else {
    fold();
    y = F::conv2d(x, folded_weight_,
                  F::Conv2dFuncOptions().bias(folded_bias_).stride(stride_).padding(padding_).groups(groups_));
  }
  return relu ? torch::relu_(y) : y;
}

DepthwiseSeparableImpl::DepthwiseSeparableImpl(int in, int out, int stride) : residual(in == out && stride == 1) {
  depthwise = register_module("depthwise", ConvBnRelu(in, in, 3, stride, in));
  // No ReLU after the projection when the block is residual (MobileNetV2's linear bottleneck).
  pointwise = register_module("pointwise", ConvBnRelu(in, out, 1, 1, 1, !residual));
}

torch::Tensor DepthwiseSeparableImpl::forward(const torch::Tensor& x) {
  auto y = pointwise(depthwise(x));
  return residual ? torch::relu(y + x) : y;
}

TransformerBlockImpl::TransformerBlockImpl(int channels, int heads) {
  position = register_module(
      "position", torch::nn::Conv2d(torch::nn::Conv2dOptions(channels, channels, 3).padding(1).groups(channels)));
  norm1 = register_module("norm1", torch::nn::LayerNorm(torch::nn::LayerNormOptions({channels})));
  norm2 = register_module("norm2", torch::nn::LayerNorm(torch::nn::LayerNormOptions({channels})));
  attention = register_module("attention", torch::nn::MultiheadAttention(channels, heads));
  fc1 = register_module("fc1", torch::nn::Linear(channels, 2 * channels));
  fc2 = register_module("fc2", torch::nn::Linear(2 * channels, channels));
}

torch::Tensor TransformerBlockImpl::forward(const torch::Tensor& x) {
  const auto N = x.size(0), C = x.size(1), H = x.size(2), W = x.size(3);
  auto y = x + position(x);
  auto tokens = y.flatten(2).permute({2, 0, 1});  // (H*W) x N x C: every cell attends to every cell
  auto q = norm1(tokens);
  auto attended = std::get<0>(attention(q, q, q, torch::Tensor(), /*need_weights=*/false));
  tokens = tokens + attended;
  tokens = tokens + fc2(torch::gelu(fc1(norm2(tokens))));
  return tokens.permute({1, 2, 0}).reshape({N, C, H, W});
}

LwdNetworkImpl::LwdNetworkImpl(const NetworkOptions& opt, int in_channels,
                               const std::map<int, int>& head_channels_per_stride)
    : options(opt) {
  stem = register_module("stem", ConvBnRelu(in_channels, opt.stem_channels, 3, 2));
  int ch = opt.stem_channels;
  for (std::size_t i = 0; i < opt.stage_channels.size(); ++i) {
    torch::nn::Sequential stage;
    stage->push_back(DepthwiseSeparable(ch, opt.stage_channels[i], 2));
    for (int b = 1; b < opt.stage_blocks[i]; ++b)
      stage->push_back(DepthwiseSeparable(opt.stage_channels[i], opt.stage_channels[i], 1));
    stages.push_back(register_module("stage" + std::to_string(i), stage));
    ch = opt.stage_channels[i];
  }
  transformer = torch::nn::Sequential();
  for (int l = 0; l < opt.attention_layers; ++l) transformer->push_back(TransformerBlock(ch, opt.attention_heads));
  register_module("transformer", transformer);

  // Decoder: from the coarsest stage down to the finest head stride.
  int finest = head_channels_per_stride.begin()->first;
  const int S = static_cast<int>(opt.stage_channels.size());
  for (int i = S - 1; i >= 0; --i) {
    const int stride = opt.stageStride(i);
    if (stride < finest) break;
    laterals.emplace(stride, register_module("lateral" + std::to_string(stride),
                                             torch::nn::Conv2d(torch::nn::Conv2dOptions(opt.stage_channels[i],
                                                                                        opt.decoder_channels, 1))));
    if (i < S - 1)
      fuse.emplace(stride, register_module("fuse" + std::to_string(stride),
                                           DepthwiseSeparable(opt.decoder_channels, opt.decoder_channels, 1)));
  }
  for (const auto& [stride, out] : head_channels_per_stride) {
    torch::nn::Sequential h(DepthwiseSeparable(opt.decoder_channels, opt.head_channels, 1),
                            torch::nn::Conv2d(torch::nn::Conv2dOptions(opt.head_channels, out, 1)));
    heads.emplace(stride, register_module("head" + std::to_string(stride), h));
  }
}

NetworkOutput LwdNetworkImpl::forward(const torch::Tensor& bev) {
  std::vector<torch::Tensor> enc;
  auto x = stem(bev);
  for (auto& s : stages) {
    x = s->forward(x);
    enc.push_back(x);
  }
  if (!transformer->is_empty()) enc.back() = transformer->forward(enc.back());

  NetworkOutput out;
  const int S = static_cast<int>(enc.size());
  torch::Tensor top;
  std::map<int, torch::Tensor> decoded;
  for (int i = S - 1; i >= 0; --i) {
    const int stride = options.stageStride(i);
    auto lat = laterals.find(stride);
    if (lat == laterals.end()) break;
    auto l = lat->second(enc[i]);
    if (!top.defined()) {
      top = l;
    } else {
      auto up = F::interpolate(top, F::InterpolateFuncOptions()
                                        .size(std::vector<int64_t>{l.size(2), l.size(3)})
                                        .mode(torch::kNearest));
      top = fuse.at(stride)(up + l);
    }
    decoded[stride] = top;
  }
  for (auto& [stride, h] : heads) out.head[stride] = h->forward(decoded.at(stride));
  out.features = decoded.at(heads.begin()->first);
  return out;
}

void LwdNetworkImpl::initClassificationBias(int stride, int first, int count, int period, double prior, int end) {
  auto& seq = heads.at(stride);
  auto conv = seq->ptr(seq->size() - 1)->as<torch::nn::Conv2dImpl>();
  torch::NoGradGuard ng;
  const double b = -std::log((1.0 - prior) / prior);
  const int total = end > 0 ? end : static_cast<int>(conv->bias.size(0));
  for (int start = first; start < total; start += period)
    for (int k = 0; k < count && start + k < total; ++k) conv->bias[start + k].fill_(b);
}

std::int64_t parameterCount(const torch::nn::Module& m) {
  std::int64_t n = 0;
  for (const auto& p : m.parameters()) n += p.numel();
  return n;
}

}  // namespace nn
}  // namespace ret3d
