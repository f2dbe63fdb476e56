// Training IntraRM: Ret3D eq. (5) and AdamW (the paper's optimiser, lr 3e-4, weight decay 0.01).
#include "ret3d/relation/intra_rm_learner.h"

#include <array>
#include <cmath>
#include <numeric>
#include <random>
#include <stdexcept>

#include "intra_rm_network.h"
#include "learner_checkpoint.h"
#include "ret3d/core/geometry.h"
#include "ret3d/core/log.h"

namespace ret3d {
namespace relation {

using Learner = IntraRMLearner::Impl;

std::ostream& operator<<(std::ostream& out, const IntraRMLoss& loss) {
  return out << "(cls " << loss.cls << " reg " << loss.reg << " dir " << loss.dir << ")";
}

// refine_boxes only changes what refine() applies: a checkpoint trained either way fits.
bool sameNetwork(const IntraRMArch& a, const IntraRMArch& b) {
  return a.feature_dim == b.feature_dim && a.hidden == b.hidden && a.rounds == b.rounds &&
         a.head_hidden == b.head_hidden && a.radius == b.radius && a.use_edges == b.use_edges;
}

// Loss of eq. (5) over a batch of frames.
std::pair<torch::Tensor, IntraRMLoss> batchLoss(Learner& learner, const std::vector<const IntraRMFrame*>& batch) {
  std::vector<const Detections*> dets;
  for (const IntraRMFrame* f : batch) dets.push_back(&f->detections);
  const IntraRMInputs in = makeIntraRMInputs(dets, learner.config.model);
  const int64_t n = static_cast<int64_t>(in.nodes);
  torch::Tensor cls_t = torch::zeros({n, 3}), cls_w = torch::zeros({n, 1}), reg_m = torch::zeros({n});
  torch::Tensor loc_t = torch::zeros({n, 3}), box_t = torch::zeros({n, 4});
  auto ct = cls_t.accessor<float, 2>();
  auto cw = cls_w.accessor<float, 2>();
  auto rm = reg_m.accessor<float, 1>();
  auto lt = loc_t.accessor<float, 2>();
  auto bt = box_t.accessor<float, 2>();
  int64_t i = 0;
  double positives = 0;
  for (const IntraRMFrame* f : batch) {
    for (const IntraRMTarget& t : f->targets) {
      for (int k = 0; k < 3; ++k) ct[i][k] = t.cls[k];
      cw[i][0] = t.cls_weight;
      positives += (t.cls[0] + t.cls[1] + t.cls[2]) > 0 ? t.cls_weight : 0;
      if (t.regress) {
        rm[i] = 1;
        lt[i][0] = t.dx, lt[i][1] = t.dy, lt[i][2] = t.dz;
        bt[i][0] = t.dyaw, bt[i][1] = t.dl, bt[i][2] = t.dw, bt[i][3] = t.dh;
      }
      ++i;
    }
  }
  const IntraRMOutput out = learner.net()->forward(in.basic, in.feat, in.source, in.target);
  // Focal loss (Lin et al.), sigmoid per class channel, normalised by the number of positives.
  const double alpha = learner.config.train.focal_alpha, gamma = learner.config.train.focal_gamma;
  const torch::Tensor p = torch::sigmoid(out.cls);
  const torch::Tensor ce = torch::binary_cross_entropy_with_logits(out.cls, cls_t, {}, {}, at::Reduction::None);
  const torch::Tensor p_t = p * cls_t + (1 - p) * (1 - cls_t);
  const torch::Tensor a_t = alpha * cls_t + (1 - alpha) * (1 - cls_t);
  const torch::Tensor l_cls = (a_t * torch::pow(1 - p_t, gamma) * ce * cls_w).sum() / std::max(1.0, positives);
  // Smooth-L1 on location (centre and log size: the box's place and extent) and on heading, over regressed boxes.
  const double n_reg = std::max(1.0, reg_m.sum().item<double>());
  const torch::Tensor m = reg_m.unsqueeze(1);
  // Both sides in the units of the residuals' spread (IntraRMNetImpl::loc_scale, box_scale).
  const torch::Tensor ls = learner.net()->loc_scale, bs = learner.net()->box_scale;
  const torch::Tensor pred_reg = torch::cat({out.loc / ls, (out.box / bs).slice(1, 1, 4)}, 1);
  const torch::Tensor t_reg = torch::cat({loc_t / ls, (box_t / bs).slice(1, 1, 4)}, 1);
  const torch::Tensor l_reg = (torch::smooth_l1_loss(pred_reg, t_reg, at::Reduction::None) * m).sum() / n_reg;
  const torch::Tensor l_dir = (torch::smooth_l1_loss((out.box / bs).slice(1, 0, 1), (box_t / bs).slice(1, 0, 1),
                                                     at::Reduction::None) *
                               m)
                                  .sum() /
                              n_reg;
  const IntraRMTrainConfig& tc = learner.config.train;
  const torch::Tensor total = l_cls + tc.loc_weight * l_reg + tc.dir_weight * l_dir;
  IntraRMLoss L;
  L.total = total.item<double>();
  L.cls = l_cls.item<double>();
  L.reg = l_reg.item<double>();
  L.dir = l_dir.item<double>();
  L.positives = static_cast<std::size_t>(positives);
  L.nodes = in.nodes;
  return {total, L};
}

void fitInputNormalisation(Learner& learner, const std::vector<IntraRMFrame>& frames) {
  const IntraRMArch& a = learner.config.model;
  std::vector<double> sum(kIntraBasicFeatures, 0), sq(kIntraBasicFeatures, 0);
  std::vector<double> fsum(a.feature_dim, 0), fsq(a.feature_dim, 0);
  double count = 0;
  float f[kIntraBasicFeatures];
  for (const IntraRMFrame& fr : frames) {
    if (a.feature_dim > 0 && fr.detections.feature_dim != a.feature_dim)
      throw std::invalid_argument("IntraRM training: a frame has feature_dim " +
                                  std::to_string(fr.detections.feature_dim) + ", the model " +
                                  std::to_string(a.feature_dim));
    for (std::size_t i = 0; i < fr.detections.size(); ++i) {
      basicFeatures(fr.detections.boxes[i], f);
      for (int k = 0; k < kIntraBasicFeatures; ++k) sum[k] += f[k], sq[k] += double(f[k]) * f[k];
      for (std::size_t k = 0; k < a.feature_dim; ++k) {
        const double v = fr.detections.feature(i)[k];
        fsum[k] += v, fsq[k] += v * v;
      }
      ++count;
    }
  }
  if (count < 2) return;
  auto stats = [&](const std::vector<double>& s, const std::vector<double>& q, torch::Tensor& mean,
                   torch::Tensor& stdev, const std::vector<bool>& keep) {
    for (std::size_t k = 0; k < s.size(); ++k) {
      if (!keep.empty() && !keep[k]) continue;  // heading sin/cos and one-hot are already in [-1, 1]
      const double mu = s[k] / count;
      const double sd = std::sqrt(std::max(0.0, q[k] / count - mu * mu));
      mean[static_cast<int64_t>(k)] = mu;
      stdev[static_cast<int64_t>(k)] = sd > 1e-6 ? sd : 1.0;
    }
  };
  torch::NoGradGuard no_grad;
  auto& net = learner.net();
  std::vector<bool> keep(kIntraBasicFeatures, true);
  for (int k : {6, 7, 11, 12, 13}) keep[static_cast<std::size_t>(k)] = false;
  stats(sum, sq, net->basic_mean, net->basic_std, keep);
  stats(fsum, fsq, net->feat_mean, net->feat_std, {});
  // Spread (root mean square) of the regression targets.
  double rs[7] = {0, 0, 0, 0, 0, 0, 0}, nr = 0;
  for (const IntraRMFrame& fr : frames) {
    for (const IntraRMTarget& t : fr.targets) {
      if (!t.regress) continue;
      const double v[7] = {t.dx, t.dy, t.dz, t.dyaw, t.dl, t.dw, t.dh};
      for (int k = 0; k < 7; ++k) rs[k] += v[k] * v[k];
      ++nr;
    }
  }
  if (nr >= 2) {
    for (int k = 0; k < 7; ++k) {
      const double r = std::max(1e-3, std::sqrt(rs[k] / nr));
      if (k < 3) net->loc_scale[k] = r;
      else net->box_scale[k - 3] = r;
    }
  }
}

std::vector<IntraRMFrame> augmented(Learner& learner, const std::vector<const IntraRMFrame*>& batch) {
  const auto& tc = learner.config.train;
  // Augmentation: one rotation about the sensor's z axis and an optional mirror (y -> -y) per frame, applied to the
  // boxes and to the regression targets alike (size residuals are invariant; centre residuals turn with the frame;
  // the heading residual changes sign under the mirror).
  std::vector<IntraRMFrame> frames(batch.size());
  std::uniform_real_distribution<double> rot(-tc.augment_rotation, tc.augment_rotation);
  std::bernoulli_distribution flip(0.5);
  for (std::size_t f = 0; f < batch.size(); ++f) {
    frames[f] = *batch[f];
    const double th = tc.augment_rotation > 0 ? rot(learner.rng) : 0.0;
    const bool mirror = tc.augment_flip && flip(learner.rng);
    const double c = std::cos(th), s = std::sin(th);
    auto turn = [&](double& x, double& y) {
      if (mirror) y = -y;
      const double nx = c * x - s * y, ny = s * x + c * y;
      x = nx, y = ny;
    };
    for (Box& b : frames[f].detections.boxes) {
      turn(b.x, b.y);
      turn(b.vx, b.vy);
      b.yaw = wrapAngle((mirror ? -b.yaw : b.yaw) + th);
    }
    for (IntraRMTarget& t : frames[f].targets) {
      double dx = t.dx, dy = t.dy;
      turn(dx, dy);
      t.dx = static_cast<float>(dx), t.dy = static_cast<float>(dy);
      if (mirror) t.dyaw = -t.dyaw;
    }
  }
  return frames;
}

// The mean over batches of frames_per_batch frames.
IntraRMLoss meanLoss(Learner& learner, const std::vector<IntraRMFrame>& frames) {
  IntraRMLoss sum;
  double batches = 0;
  const std::size_t bs = static_cast<std::size_t>(learner.config.train.frames_per_batch);
  for (std::size_t b = 0; b < frames.size(); b += bs) {
    std::vector<const IntraRMFrame*> batch;
    for (std::size_t f = b; f < std::min(frames.size(), b + bs); ++f) batch.push_back(&frames[f]);
    const IntraRMLoss L = batchLoss(learner, batch).second;
    sum.total += L.total, sum.cls += L.cls, sum.reg += L.reg, sum.dir += L.dir;
    sum.positives += L.positives, sum.nodes += L.nodes;
    ++batches;
  }
  if (batches > 0) sum.total /= batches, sum.cls /= batches, sum.reg /= batches, sum.dir /= batches;
  return sum;
}

template class RelationLearner<IntraRM, IntraRMFrame, IntraRMLoss>;

namespace {

// Logistic regression p = sigmoid(a z + b) of targets t on logits z by Newton's method (a tiny ridge keeps the
// Hessian invertible); halves a step that does not lower the loss.
std::pair<double, double> fitPlatt(const std::vector<double>& z, const std::vector<double>& t) {
  double a = 1, b = 0;
  auto loss = [&](double pa, double pb) {
    double l = 1e-6 * (pa * pa + pb * pb);
    for (std::size_t i = 0; i < z.size(); ++i) {
      const double u = pa * z[i] + pb;
      l += std::max(u, 0.0) - u * t[i] + std::log1p(std::exp(-std::abs(u)));  // BCE with logits, stable
    }
    return l;
  };
  double current = loss(a, b);
  for (int iter = 0; iter < 100; ++iter) {
    double ga = 2e-6 * a, gb = 2e-6 * b, haa = 2e-6, hab = 0, hbb = 2e-6;
    for (std::size_t i = 0; i < z.size(); ++i) {
      const double p = 1.0 / (1.0 + std::exp(-(a * z[i] + b))), w = p * (1 - p), r = p - t[i];
      ga += r * z[i], gb += r;
      haa += w * z[i] * z[i], hab += w * z[i], hbb += w;
    }
    const double det = haa * hbb - hab * hab;
    if (!(det > 0)) break;
    double da = (hbb * ga - hab * gb) / det, db = (haa * gb - hab * ga) / det;
    double next = loss(a - da, b - db);
    for (int half = 0; half < 30 && next > current; ++half) da /= 2, db /= 2, next = loss(a - da, b - db);
    if (next > current) break;
    a -= da, b -= db;
    const bool done = current - next < 1e-10 * std::max(1.0, current);
    current = next;
    if (done) break;
  }
  return {a, b};
}

}  // namespace

PerClass<std::size_t> calibrateIntraRMScores(IntraRM* model, const std::vector<IntraRMFrame>& frames) {
  IntraRMArch& arch = model->impl().info.config.model;
  std::array<std::vector<double>, 3> z, t;
  torch::InferenceMode guard;
  for (const IntraRMFrame& f : frames) {
    if (f.detections.empty()) continue;
    const IntraRMInputs in = makeIntraRMInputs({&f.detections}, arch);
    const torch::Tensor cls = model->impl().net->forward(in.basic, in.feat, in.source, in.target).cls.contiguous();
    const float* pc = cls.data_ptr<float>();
    for (std::size_t i = 0; i < f.detections.size(); ++i) {
      const int c = classIndex(f.detections.boxes[i].label);
      if (c < 0 || f.targets[i].cls_weight <= 0) continue;
      z[static_cast<std::size_t>(c)].push_back(pc[3 * i + static_cast<std::size_t>(c)]);
      t[static_cast<std::size_t>(c)].push_back(f.targets[i].cls[static_cast<std::size_t>(c)] > 0 ? 1.0 : 0.0);
    }
  }
  PerClass<std::size_t> used;
  for (std::size_t c = 0; c < 3; ++c) {
    const double positives = std::accumulate(t[c].begin(), t[c].end(), 0.0);
    used[c] = z[c].size();
    if (positives < 1 || positives > static_cast<double>(z[c].size()) - 1) {
      arch.score_scale[c] = 1, arch.score_bias[c] = 0;
      continue;
    }
    const auto [a, b] = fitPlatt(z[c], t[c]);
    const bool increasing = a > 0 && std::isfinite(a) && std::isfinite(b);
    if (!increasing)  // a network whose scores do not rank this class: its scores are left as they are
      RET3D_WARN("IntraRM score calibration: " << className(kDetectedClasses[c]) << "'s scores do not rise with its "
                                               << "true positives (slope " << a << "); left uncalibrated");
    arch.score_scale[c] = increasing ? a : 1.0, arch.score_bias[c] = increasing ? b : 0.0;
  }
  arch.validate();
  return used;
}

}  // namespace relation
}  // namespace ret3d
