// Training InterRM: the smooth-L1 loss L_inter of Ret3D §3.3 on the current box's residuals, AdamW (lr 3e-4, weight
// decay 0.01, 64 sequences per batch: the paper's settings).
#include "ret3d/relation/inter_rm_learner.h"

#include <cmath>
#include <random>
#include <stdexcept>

#include "inter_rm_network.h"
#include "learner_checkpoint.h"
#include "ret3d/core/geometry.h"

namespace ret3d {
namespace relation {

std::array<float, 7> interResiduals(const Box& c, const Box& t) {
  const double cs = std::cos(c.yaw), sn = std::sin(c.yaw);
  const double dx = t.x - c.x, dy = t.y - c.y;
  // The KITTI IoU ignores the direction: the heading residual is taken modulo pi, within [-pi/2, pi/2).
  double dyaw = wrapAngle(t.yaw - c.yaw);
  if (dyaw >= M_PI / 2) dyaw -= M_PI;
  if (dyaw < -M_PI / 2) dyaw += M_PI;
  return {{static_cast<float>(cs * dx + sn * dy), static_cast<float>(-sn * dx + cs * dy),
           static_cast<float>(t.z - c.z), static_cast<float>(std::log(t.length / c.length)),
           static_cast<float>(std::log(t.width / c.width)), static_cast<float>(std::log(t.height / c.height)),
           static_cast<float>(dyaw)}};
}

using Learner = InterRMLearner::Impl;

std::ostream& operator<<(std::ostream& out, const InterRMLoss& loss) {
  return out << "(loc " << loss.loc << " size " << loss.size << " yaw " << loss.yaw << ")";
}

bool sameNetwork(const InterRMArch& a, const InterRMArch& b) {
  return a.c_enc == b.c_enc && a.heads == b.heads && a.ffn_expansion == b.ffn_expansion &&
         a.positional_encoding == b.positional_encoding && a.max_history == b.max_history &&
         a.regress_size == b.regress_size;
}

std::pair<torch::Tensor, InterRMLoss> batchLoss(Learner& learner, const std::vector<const InterRMSample*>& batch) {
  const InterRMConfig& config = learner.config;
  std::vector<const InterRMSequence*> seqs;
  torch::Tensor target = torch::zeros({static_cast<int64_t>(batch.size()), kInterOutputs});
  auto acc = target.accessor<float, 2>();
  for (std::size_t i = 0; i < batch.size(); ++i) {
    seqs.push_back(&batch[i]->sequence);
    const auto r = interResiduals(batch[i]->sequence.boxes.at(0), batch[i]->target);
    for (int k = 0; k < kInterOutputs; ++k) acc[static_cast<int64_t>(i)][k] = r[static_cast<std::size_t>(k)];
  }
  const torch::Tensor pred = learner.net()->forward(makeInterRMInputs(seqs, config.model.max_history));
  torch::Tensor l = torch::smooth_l1_loss(pred, target, at::Reduction::None, config.train.smooth_l1_beta);
  if (!config.model.regress_size) {  // the size outputs are not used: no loss on them
    torch::Tensor w = torch::ones({1, kInterOutputs});
    w.slice(1, 3, 6).zero_();
    l = l * w;
  }
  const torch::Tensor per = l.sum(1);  // per sequence: all seven residuals
  const torch::Tensor total = per.mean();
  InterRMLoss L;
  L.total = total.item<double>();
  L.loc = l.slice(1, 0, 3).sum(1).mean().item<double>();
  L.size = l.slice(1, 3, 6).sum(1).mean().item<double>();
  L.yaw = l.slice(1, 6, 7).sum(1).mean().item<double>();
  L.sequences = batch.size();
  return {total, L};
}

void fitInputNormalisation(Learner& learner, const std::vector<InterRMSample>& samples) {
  std::vector<double> sum(kInterBasicFeatures, 0), sq(kInterBasicFeatures, 0);
  double count = 0;
  float f[kInterBasicFeatures];
  const std::size_t max_h = static_cast<std::size_t>(learner.config.model.max_history);
  for (const InterRMSample& s : samples) {
    for (std::size_t k = 0; k < std::min(max_h, s.sequence.boxes.size()); ++k) {
      interBasicFeatures(s.sequence, k, f);
      for (int j = 0; j < kInterBasicFeatures; ++j) sum[j] += f[j], sq[j] += double(f[j]) * f[j];
      ++count;
    }
  }
  if (count < 2) return;
  torch::NoGradGuard no_grad;
  auto& net = learner.net();
  for (int j = 0; j < kInterBasicFeatures; ++j) {
    if (j == 6 || j == 7 || (j >= 11 && j <= 13)) continue;  // heading sin/cos and one-hot are already in [-1, 1]
    const double mu = sum[j] / count;
    const double sd = std::sqrt(std::max(0.0, sq[j] / count - mu * mu));
    net->feat_mean[j] = mu;
    net->feat_std[j] = sd > 1e-6 ? sd : 1.0;
  }
}

// Mirrors the whole scene (y -> -y) with probability 0.5; features and residuals follow.
std::vector<InterRMSample> augmented(Learner& learner, const std::vector<const InterRMSample*>& batch) {
  std::vector<InterRMSample> copies;
  copies.reserve(batch.size());
  std::bernoulli_distribution flip(0.5);
  auto mirror = [](Box& b) {
    b.y = -b.y;
    b.vy = -b.vy;
    b.yaw = wrapAngle(-b.yaw);
  };
  for (const InterRMSample* s : batch) {
    copies.push_back(*s);
    if (learner.config.train.augment_flip && flip(learner.rng)) {
      for (Box& b : copies.back().sequence.boxes) mirror(b);
      mirror(copies.back().target);
    }
  }
  return copies;
}

// The mean per sequence, in batches of 256.
InterRMLoss meanLoss(Learner& learner, const std::vector<InterRMSample>& samples) {
  InterRMLoss sum;
  const std::size_t bs = 256;
  for (std::size_t s = 0; s < samples.size(); s += bs) {
    std::vector<const InterRMSample*> batch;
    for (std::size_t i = s; i < std::min(samples.size(), s + bs); ++i) batch.push_back(&samples[i]);
    const InterRMLoss L = batchLoss(learner, batch).second;
    const double n = static_cast<double>(batch.size());
    sum.total += L.total * n, sum.loc += L.loc * n, sum.size += L.size * n, sum.yaw += L.yaw * n;
    sum.sequences += batch.size();
  }
  if (sum.sequences > 0) {
    const double n = static_cast<double>(sum.sequences);
    sum.total /= n, sum.loc /= n, sum.size /= n, sum.yaw /= n;
  }
  return sum;
}

template class RelationLearner<InterRM, InterRMSample, InterRMLoss>;

}  // namespace relation
}  // namespace ret3d
