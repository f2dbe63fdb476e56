#include "ret3d/detector/nn/network.h"

#include <algorithm>
#include <chrono>
#include <cstdlib>
#include <tuple>
#include <vector>

#include <gtest/gtest.h>

namespace ret3d {
namespace {

TEST(LwdNetwork, OutputShapesAtEveryHeadStride) {
  torch::manual_seed(0);
  NetworkOptions o;
  nn::LwdNetwork net(o, 6, std::map<int, int>{{4, 20}, {8, 30}});
  net->eval();
  torch::NoGradGuard ng;
  const auto out = net->forward(torch::rand({2, 6, 128, 96}));
  ASSERT_EQ(out.head.size(), 2u);
  EXPECT_EQ(out.head.at(4).sizes(), (std::vector<int64_t>{2, 20, 32, 24}));
  EXPECT_EQ(out.head.at(8).sizes(), (std::vector<int64_t>{2, 30, 16, 12}));
  EXPECT_EQ(out.features.sizes(), (std::vector<int64_t>{2, o.decoder_channels, 32, 24}));
  // Another grid size (multi-scale training) runs through the same modules.
  const auto out2 = net->forward(torch::rand({1, 6, 64, 64}));
  EXPECT_EQ(out2.head.at(8).sizes(), (std::vector<int64_t>{1, 30, 8, 8}));
  EXPECT_GT(nn::parameterCount(*net), 10000);
}

// In eval mode ConvBnRelu folds its BatchNorm into the convolution: the same output as convolution then BatchNorm,
// for depthwise and pointwise layers, strided or not, and again after the weights or statistics change (a model
// shared with training, or loaded).
TEST(ConvBnRelu, FoldedBatchNormGivesTheSameOutputAndFollowsChanges) {
  torch::manual_seed(3);
  torch::NoGradGuard ng;
  for (const auto& [in, out, kernel, stride, groups] :
       std::vector<std::tuple<int, int, int, int, int>>{{8, 8, 3, 1, 8}, {8, 16, 3, 2, 8}, {8, 12, 1, 1, 1}}) {
    nn::ConvBnRelu layer(in, out, kernel, stride, groups, /*relu=*/false);
    auto randomise = [&] {
      layer->conv->weight.normal_();
      layer->bn->weight.uniform_(0.5, 2.0);
      layer->bn->bias.normal_();
      layer->bn->running_mean.normal_();
      layer->bn->running_var.uniform_(0.2, 3.0);
    };
    randomise();
    layer->eval();
    const auto x = torch::randn({2, in, 20, 18});
    const auto reference = [&] { return layer->bn(layer->conv(x)); };
    EXPECT_TRUE(torch::allclose(layer->forward(x), reference(), 1e-4, 1e-4)) << in << " -> " << out;
    randomise();  // in place, as an optimiser step or loading does
    EXPECT_TRUE(torch::allclose(layer->forward(x), reference(), 1e-4, 1e-4)) << "after a change";
  }
}

TEST(LwdNetwork, AttentionMixesDistantCells) {
  // With the transformer block, a change in one corner of the input reaches the opposite corner of the coarse map,
  // which the convolutions alone (receptive field of a few cells) cannot do.
  torch::manual_seed(1);
  NetworkOptions o;
  o.stage_blocks = {1, 1, 1};
  nn::LwdNetwork with(o, 6, std::map<int, int>{{16, 4}});
  o.attention_layers = 0;
  nn::LwdNetwork without(o, 6, std::map<int, int>{{16, 4}});
  with->eval();
  without->eval();
  torch::NoGradGuard ng;
  auto a = torch::zeros({1, 6, 256, 256});
  auto b = a.clone();
  b.index_put_({0, torch::indexing::Slice(), torch::indexing::Slice(0, 8), torch::indexing::Slice(0, 8)}, 1.0);
  auto corner = [](const torch::Tensor& t) { return t.index({0, torch::indexing::Slice(), -1, -1}); };
  EXPECT_GT((corner(with->forward(a).head.at(16)) - corner(with->forward(b).head.at(16))).abs().max().item<float>(), 1e-6);
  EXPECT_LT((corner(without->forward(a).head.at(16)) - corner(without->forward(b).head.at(16))).abs().max().item<float>(), 1e-7);
}

// Latency of the default configuration (RET3D_BENCH_GRID=<cells> to try other sizes); prints the figure. A
// measurement, disabled in the suite: run with --gtest_also_run_disabled_tests --gtest_filter=*Latency*.
TEST(LwdNetwork, DISABLED_LatencyAtTheDefaultGrid) {
  torch::set_num_threads(2);
  ModelConfig m;
  int grid = m.geometry.width();
  if (const char* g = std::getenv("RET3D_BENCH_GRID")) grid = std::atoi(g);
  std::map<int, int> heads = {{4, 13}};
  nn::LwdNetwork net(m.network, 6, heads);
  net->eval();
  torch::NoGradGuard ng;
  auto x = (torch::rand({1, 6, grid, grid}) > 0.9).to(torch::kFloat);
  std::vector<double> ms;
  for (int i = 0; i < 8; ++i) {
    const auto t0 = std::chrono::steady_clock::now();
    net->forward(x);
    ms.push_back(std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count());
  }
  std::sort(ms.begin() + 1, ms.end());
  std::printf("network forward %dx%d, 2 threads: median %.1f ms, %lld parameters\n", grid, grid, ms[1 + ms.size() / 2 - 1],
              static_cast<long long>(nn::parameterCount(*net)));
}

}  // namespace
}  // namespace ret3d
