#include "ret3d/detector/nn/heads.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "ret3d/core/geometry.h"
#include "ret3d/detector/box_coder.h"

namespace ret3d {
namespace nn {

namespace F = torch::nn::functional;
using torch::indexing::Slice;

double gaussianRadius(double h, double w, double o) {
  const double b1 = h + w, c1 = w * h * (1 - o) / (1 + o);
  const double r1 = (b1 + std::sqrt(b1 * b1 - 4 * c1)) / 2;
  const double b2 = 2 * (h + w), c2 = (1 - o) * w * h;
  const double r2 = (b2 + std::sqrt(b2 * b2 - 16 * c2)) / 2;
  const double a3 = 4 * o, b3 = -2 * o * (h + w), c3 = (o - 1) * w * h;
  const double r3 = (b3 + std::sqrt(b3 * b3 - 4 * a3 * c3)) / 2;
  return std::min({r1, r2, r3});
}

torch::Tensor supervisionMask(const GroundTruth& gt, const BevGeometry& g, int stride, int h, int w) {
  auto mask = torch::ones({h, w});
  if (gt.ignore.empty() && gt.ignore_regions.empty() && gt.supervised_fov_deg <= 0 && !gt.labelled_view) return mask;
  auto m = mask.accessor<float, 2>();
  const double half_fov = 0.5 * gt.supervised_fov_deg * M_PI / 180.0;
  for (int v = 0; v < h; ++v)
    for (int u = 0; u < w; ++u) {
      const Eigen::Vector2d p = g.featureToMetric(u + 0.5, v + 0.5, stride);
      if (half_fov > 0 && std::abs(std::atan2(p.y(), p.x())) > half_fov) m[v][u] = 0;
      if (gt.labelled_view && !gt.labelled_view->contains(p)) m[v][u] = 0;
      for (const BevWedge& r : gt.ignore_regions)
        if (m[v][u] != 0 && r.contains(p)) m[v][u] = 0;
      for (const Box& b : gt.ignore)
        if (pointInBox(b, Eigen::Vector3d(p.x(), p.y(), b.z))) m[v][u] = 0;
    }
  return mask;
}

namespace {

int classIndex(const std::vector<ObjectClass>& classes, ObjectClass c) {
  for (std::size_t i = 0; i < classes.size(); ++i)
    if (classes[i] == c) return static_cast<int>(i);
  return -1;
}

bool velocityValid(const GroundTruth& gt, std::size_t i) {
  return gt.velocity_valid.empty() || gt.velocity_valid[i];
}

// Sigmoid focal loss (RetinaNet), summed, per-element weighted.
torch::Tensor sigmoidFocal(const torch::Tensor& logits, const torch::Tensor& target, const torch::Tensor& weight,
                           double alpha = 0.25, double gamma = 2.0) {
  auto p = torch::sigmoid(logits);
  auto ce = F::binary_cross_entropy_with_logits(logits, target,
                                                F::BinaryCrossEntropyWithLogitsFuncOptions().reduction(torch::kNone));
  auto pt = p * target + (1 - p) * (1 - target);
  auto a = alpha * target + (1 - alpha) * (1 - target);
  return (a * (1 - pt).pow(gamma) * ce * weight).sum();
}

// Flat indices and scores of the cells of class c above its candidate threshold, at most max_candidates of the best;
// false if none.
bool selectCandidates(const torch::Tensor& scores, ObjectClass c, const InferenceOptions& o, torch::Tensor* keep,
                      torch::Tensor* vals) {
  *keep = torch::nonzero(scores > o.candidateThreshold(c)).view({-1});
  if (keep->numel() == 0) return false;
  *vals = scores.index({*keep});
  if (keep->numel() > o.max_candidates) {
    auto top = torch::topk(*vals, o.max_candidates);
    *keep = keep->index({std::get<1>(top)});
    *vals = std::get<0>(top);
  }
  return true;
}

// Regression (smooth L1 on the box code, velocity separately where known), averaged over positives.
void regressionLosses(const torch::Tensor& pred, const torch::Tensor& target, const torch::Tensor& vel_valid,
                      const TrainOptions& t, torch::Tensor* total, std::vector<std::pair<std::string, double>>* parts) {
  const double P = std::max<int64_t>(1, pred.size(0));
  auto sl1 = [](const torch::Tensor& a, const torch::Tensor& b) {
    return F::smooth_l1_loss(a, b, F::SmoothL1LossFuncOptions().reduction(torch::kNone).beta(1.0 / 9.0));
  };
  auto reg = sl1(pred.index({Slice(), Slice(0, 8)}), target.index({Slice(), Slice(0, 8)})).sum() / P;
  auto vel = (sl1(pred.index({Slice(), Slice(8, 10)}), target.index({Slice(), Slice(8, 10)})).sum(1) * vel_valid)
                 .sum() / std::max(1.0, vel_valid.sum().item<double>());
  *total = *total + t.loss_weight_regression * reg + t.loss_weight_velocity * vel;
  parts->emplace_back("reg", reg.item<double>());
  parts->emplace_back("vel", vel.item<double>());
}

// ---- anchor head (LWD-3D §2.4, YOLO) ------------------------------------------------------------------------------

class AnchorHead : public DetectionHead {
 public:
  AnchorHead(const ModelConfig& c, const std::vector<Anchor>& anchors) : config_(c) {
    C_ = static_cast<int>(c.classes.size());
    D_ = 1 + C_ + kBoxCodeSize;
    quality_ = c.anchor.iou_quality;
    for (int s : c.anchor.strides) per_stride_[s];
    for (const Anchor& a : anchors) {
      if (!per_stride_.count(a.stride))
        throw std::invalid_argument("anchor head: an anchor has stride " + std::to_string(a.stride) +
                                    ", which is not a head stride");
      if (classIndex(c.classes, a.label) < 0) throw std::invalid_argument("anchor head: anchor of an unknown class");
      per_stride_[a.stride].push_back(a);
    }
    for (auto it = per_stride_.begin(); it != per_stride_.end();) {
      if (it->second.empty()) throw std::invalid_argument("anchor head: no anchor at stride " + std::to_string(it->first));
      ++it;
    }
  }

  // Per stride: A blocks of D channels (objectness, classes, box code), then A IoU-quality channels if enabled.
  std::map<int, int> outputChannels() const override {
    std::map<int, int> m;
    for (const auto& [s, a] : per_stride_) m[s] = static_cast<int>(a.size()) * (D_ + (quality_ ? 1 : 0));
    return m;
  }

  void initBias(LwdNetworkImpl& net) const override {
    for (const auto& kv : per_stride_)
      net.initClassificationBias(kv.first, 0, 1, D_, 0.01, static_cast<int>(kv.second.size()) * D_);
  }

  // One stride's training targets: objectness and its weights (N A h w), and per positive its (n, a, v, u), class,
  // box code, velocity validity and object.
  struct StrideTargets {
    torch::Tensor obj_t, weight;
    std::vector<int64_t> idx_n, idx_a, idx_v, idx_u, cls;
    std::vector<float> codes, vvalid;
    std::vector<const Box*> pos_box;
  };

  // The best anchor of the box's class over all scales: its stride and index (-1: none of the class).
  std::pair<int, int> bestAnchor(const Box& b) const {
    double best_iou = -1;
    int best_stride = 0, best_a = -1;
    for (const auto& [s2, an2] : per_stride_)
      for (int a = 0; a < static_cast<int>(an2.size()); ++a) {
        if (an2[a].label != b.label) continue;
        const double iou = anchorShapeIoU(an2[a], b.length, b.width, b.height, b.z);
        if (iou > best_iou) best_iou = iou, best_stride = s2, best_a = a;
      }
    return {best_stride, best_a};
  }

  // Positives of one stride: a box's best anchor if this stride holds it, plus this stride's anchors of the class
  // that fit nearly as well (IoU >= 0.5), in the box's cell and up to neighbour_cells nearest neighbours.
  StrideTargets assignTargets(const std::vector<GroundTruth>& gt, const BevGeometry& g, int stride,
                              const std::vector<Anchor>& anchors, int N, int h, int w) const {
    const int A = static_cast<int>(anchors.size());
    StrideTargets T;
    T.obj_t = torch::zeros({N, A, h, w});
    T.weight = torch::ones({N, A, h, w});
    for (int n = 0; n < N; ++n) {
      T.weight[n].mul_(supervisionMask(gt[n], g, stride, h, w).unsqueeze(0));
      for (std::size_t bi = 0; bi < gt[n].boxes.size(); ++bi) {
        const Box& b = gt[n].boxes[bi];
        const int c = classIndex(config_.classes, b.label);
        if (c < 0) continue;
        const auto [best_stride, best_a] = bestAnchor(b);
        const Eigen::Vector2d f = g.metricToFeature(b.x, b.y, stride);
        const int u0 = static_cast<int>(std::floor(f.x())), v0 = static_cast<int>(std::floor(f.y()));
        std::vector<std::pair<int, int>> cells = {{u0, v0}};
        if (config_.anchor.neighbour_cells > 0) cells.push_back({f.x() - u0 < 0.5 ? u0 - 1 : u0 + 1, v0});
        if (config_.anchor.neighbour_cells > 1) cells.push_back({u0, f.y() - v0 < 0.5 ? v0 - 1 : v0 + 1});
        for (int a = 0; a < A; ++a) {
          if (anchors[a].label != b.label) continue;
          const bool best = stride == best_stride && a == best_a;
          if (!best && anchorShapeIoU(anchors[a], b.length, b.width, b.height, b.z) < 0.5) continue;
          for (const auto& [u, v] : cells) {
            if (u < 0 || v < 0 || u >= w || v >= h) continue;
            T.obj_t[n][a][v][u] = 1.0f;
            T.weight[n][a][v][u] = 1.0f;
            T.idx_n.push_back(n), T.idx_a.push_back(a), T.idx_v.push_back(v), T.idx_u.push_back(u), T.cls.push_back(c);
            const BoxCode code = encodeAnchorBox(b, anchors[a], u, v, stride, g, config_.sweep_interval);
            T.codes.insert(T.codes.end(), code.begin(), code.end());
            T.vvalid.push_back(velocityValid(gt[n], bi) ? 1.0f : 0.0f);
            T.pos_box.push_back(&b);
          }
        }
      }
    }
    return T;
  }

  HeadLoss loss(const NetworkOutput& out, const std::vector<GroundTruth>& gt, const BevGeometry& g,
                const TrainOptions& t) const override {
    HeadLoss L;
    L.total = torch::zeros({});
    torch::Tensor obj_sum = torch::zeros({}), cls_sum = torch::zeros({}), iou_sum = torch::zeros({});
    std::vector<torch::Tensor> preds, targets, valids;
    int64_t positives = 0;
    for (const auto& [stride, anchors] : per_stride_) {
      const auto& raw = out.head.at(stride);
      const int N = static_cast<int>(raw.size(0)), h = static_cast<int>(raw.size(2)), w = static_cast<int>(raw.size(3));
      const int A = static_cast<int>(anchors.size());
      auto r = raw.narrow(1, 0, A * D_).reshape({N, A, D_, h, w}).permute({0, 1, 3, 4, 2});  // N A h w D
      StrideTargets T = assignTargets(gt, g, stride, anchors, N, h, w);
      obj_sum = obj_sum + sigmoidFocal(r.select(4, 0), T.obj_t, T.weight);
      const int64_t P = static_cast<int64_t>(T.idx_n.size());
      positives += P;
      if (P == 0) continue;
      auto opt = torch::TensorOptions().dtype(torch::kLong);
      // The positives' (n, a, v, u), indexing the box channels and, with quality, the IoU channels.
      const std::vector<torch::Tensor> at = {torch::tensor(T.idx_n, opt), torch::tensor(T.idx_a, opt),
                                             torch::tensor(T.idx_v, opt), torch::tensor(T.idx_u, opt)};
      auto sel = r.index({at[0], at[1], at[2], at[3]});  // P x D
      cls_sum = cls_sum + F::cross_entropy(sel.index({Slice(), Slice(1, 1 + C_)}), torch::tensor(T.cls, opt),
                                           F::CrossEntropyFuncOptions().reduction(torch::kSum));
      auto reg = sel.index({Slice(), Slice(1 + C_, D_)});
      // The centre offset is 2 sigmoid - 0.5 (YOLOv5), the rest raw.
      reg = torch::cat({2 * torch::sigmoid(reg.index({Slice(), Slice(0, 2)})) - 0.5, reg.index({Slice(), Slice(2, kBoxCodeSize)})}, 1);
      if (quality_)
        iou_sum = iou_sum + qualityLoss(raw, A, reg, at, T.idx_a, T.idx_v, T.idx_u, T.pos_box, anchors, stride, g);
      preds.push_back(reg);
      targets.push_back(torch::from_blob(T.codes.data(), {P, kBoxCodeSize}).clone());
      valids.push_back(torch::tensor(T.vvalid));
    }
    const double norm = std::max<int64_t>(1, positives);
    auto obj = obj_sum / norm, cl = cls_sum / norm;
    L.total = obj + cl;
    L.parts.emplace_back("obj", obj.item<double>());
    L.parts.emplace_back("cls", cl.item<double>());
    if (quality_) {
      auto iou = iou_sum / norm;
      L.total = L.total + t.loss_weight_iou * iou;
      L.parts.emplace_back("iou", iou.item<double>());
    }
    if (!preds.empty()) {
      regressionLosses(torch::cat(preds), torch::cat(targets), torch::cat(valids), t, &L.total, &L.parts);
    } else {
      L.parts.emplace_back("reg", 0.0);
      L.parts.emplace_back("vel", 0.0);
    }
    return L;
  }

  std::vector<Box> decode(const NetworkOutput& out, int sample, const BevGeometry& g,
                          const InferenceOptions& o) const override {
    std::vector<Box> boxes;
    for (const auto& [stride, anchors] : per_stride_) {
      const auto& raw = out.head.at(stride)[sample];
      const int h = static_cast<int>(raw.size(1)), w = static_cast<int>(raw.size(2));
      const int A = static_cast<int>(anchors.size());
      auto r = raw.narrow(0, 0, A * D_).reshape({A, D_, h, w});
      auto score = torch::sigmoid(r.index({Slice(), Slice(0, 1)})) *
                   torch::softmax(r.index({Slice(), Slice(1, 1 + C_)}), 1);  // A x C x h x w
      if (quality_ && o.iou_score_power > 0) {
        const double p = o.iou_score_power;
        auto iou = torch::sigmoid(raw.narrow(0, A * D_, A)).unsqueeze(1);  // A x 1 x h x w
        score = score.pow(1 - p) * iou.pow(p);
      }
      auto reg = r.index({Slice(), Slice(1 + C_, D_)}).contiguous();       // A x 10 x h x w
      auto ra = reg.accessor<float, 4>();
      for (int c = 0; c < C_; ++c) {
        auto sc = score.index({Slice(), c}).reshape({-1});
        torch::Tensor keep, vals;
        if (!selectCandidates(sc, config_.classes[c], o, &keep, &vals)) continue;
        auto ka = keep.accessor<int64_t, 1>();
        auto va = vals.accessor<float, 1>();
        for (int64_t i = 0; i < keep.numel(); ++i) {
          const int64_t flat = ka[i];
          const int a = static_cast<int>(flat / (h * w)), v = static_cast<int>((flat / w) % h),
                    u = static_cast<int>(flat % w);
          BoxCode code;
          for (int k = 0; k < kBoxCodeSize; ++k) code[k] = ra[a][k][v][u];
          code[0] = 2.0f / (1.0f + std::exp(-code[0])) - 0.5f;
          code[1] = 2.0f / (1.0f + std::exp(-code[1])) - 0.5f;
          Box b = decodeAnchorBox(code, anchors[a], u, v, stride, g, config_.sweep_interval);
          b.label = config_.classes[c];
          b.score = va[i];
          boxes.push_back(b);
        }
      }
    }
    return boxes;
  }

 private:
  // BCE between the IoU channel at each positive and the 3D IoU of the box decoded there (prediction detached: the
  // channel learns to judge the box, not to move it) with its object.
  // at: the positives' (n, a, v, u) index tensors; idx_*: the same indices on the host.
  torch::Tensor qualityLoss(const torch::Tensor& raw, int A, const torch::Tensor& reg,
                            const std::vector<torch::Tensor>& at, const std::vector<int64_t>& idx_a,
                            const std::vector<int64_t>& idx_v,
                            const std::vector<int64_t>& idx_u, const std::vector<const Box*>& objects,
                            const std::vector<Anchor>& anchors, int stride, const BevGeometry& g) const {
    const int64_t P = static_cast<int64_t>(idx_a.size());
    auto codes = reg.detach().contiguous();
    auto ca = codes.accessor<float, 2>();
    std::vector<float> target(P);
    for (int64_t i = 0; i < P; ++i) {
      BoxCode code;
      for (int k = 0; k < kBoxCodeSize; ++k) code[k] = ca[i][k];
      const Box b = decodeAnchorBox(code, anchors[idx_a[i]], static_cast<int>(idx_u[i]), static_cast<int>(idx_v[i]),
                                    stride, g, config_.sweep_interval);
      target[i] = static_cast<float>(iou3d(b, *objects[i]));
    }
    auto q = raw.narrow(1, A * D_, A).index({at[0], at[1], at[2], at[3]});
    return F::binary_cross_entropy_with_logits(q, torch::tensor(target),
                                               F::BinaryCrossEntropyWithLogitsFuncOptions().reduction(torch::kSum));
  }

  ModelConfig config_;
  int C_ = 0, D_ = 0;
  bool quality_ = false;
  std::map<int, std::vector<Anchor>> per_stride_;
};

// ---- centre head (CenterPoint) ------------------------------------------------------------------------------------

class CenterHead : public DetectionHead {
 public:
  explicit CenterHead(const ModelConfig& c) : config_(c), C_(static_cast<int>(c.classes.size())) {}

  std::map<int, int> outputChannels() const override { return {{config_.center.stride, C_ + kBoxCodeSize}}; }

  void initBias(LwdNetworkImpl& net) const override {
    net.initClassificationBias(config_.center.stride, 0, C_, C_ + kBoxCodeSize, 0.1);
  }

  HeadLoss loss(const NetworkOutput& out, const std::vector<GroundTruth>& gt, const BevGeometry& g,
                const TrainOptions& t) const override {
    const int stride = config_.center.stride;
    const auto& raw = out.head.at(stride);
    const int N = static_cast<int>(raw.size(0)), h = static_cast<int>(raw.size(2)), w = static_cast<int>(raw.size(3));
    auto heat_t = torch::zeros({N, C_, h, w});
    auto mask = torch::ones({N, 1, h, w});
    auto ht = heat_t.accessor<float, 4>();
    std::vector<int64_t> idx_n, idx_v, idx_u;
    std::vector<float> codes, vvalid;
    const double cell = stride * g.resolution;
    for (int n = 0; n < N; ++n) {
      mask[n][0].copy_(supervisionMask(gt[n], g, stride, h, w));
      for (std::size_t bi = 0; bi < gt[n].boxes.size(); ++bi) {
        const Box& b = gt[n].boxes[bi];
        const int c = classIndex(config_.classes, b.label);
        if (c < 0) continue;
        const Eigen::Vector2d f = g.metricToFeature(b.x, b.y, stride);
        const int u = static_cast<int>(std::floor(f.x())), v = static_cast<int>(std::floor(f.y()));
        if (u < 0 || v < 0 || u >= w || v >= h) continue;
        const double r = std::max<double>(config_.center.min_radius,
                                          std::floor(gaussianRadius(b.length / cell, b.width / cell,
                                                                    config_.center.gaussian_overlap)));
        const int ri = static_cast<int>(r);
        const double sigma = (2 * r + 1) / 6.0;
        for (int dv = -ri; dv <= ri; ++dv)
          for (int du = -ri; du <= ri; ++du) {
            const int uu = u + du, vv = v + dv;
            if (uu < 0 || vv < 0 || uu >= w || vv >= h) continue;
            const float val = static_cast<float>(std::exp(-(du * du + dv * dv) / (2 * sigma * sigma)));
            ht[n][c][vv][uu] = std::max(ht[n][c][vv][uu], val);
          }
        ht[n][c][v][u] = 1.0f;
        idx_n.push_back(n), idx_v.push_back(v), idx_u.push_back(u);
        const BoxCode code = encodeCenterBox(b, u, v, stride, g, config_.sweep_interval);
        codes.insert(codes.end(), code.begin(), code.end());
        vvalid.push_back(velocityValid(gt[n], bi) ? 1.0f : 0.0f);
      }
    }
    // CenterNet's penalty-reduced focal loss over the heatmap.
    auto p = torch::sigmoid(raw.index({Slice(), Slice(0, C_)})).clamp(1e-4, 1 - 1e-4);
    auto pos = heat_t.eq(1.0f).to(torch::kFloat);
    auto neg = (1 - pos) * mask;
    auto pos_loss = (torch::log(p) * (1 - p).pow(2) * pos).sum();
    auto neg_loss = (torch::log(1 - p) * p.pow(2) * (1 - heat_t).pow(4) * neg).sum();
    const double P = std::max<double>(1.0, pos.sum().item<double>());
    auto heat = -(pos_loss + neg_loss) / P;
    HeadLoss L;
    L.total = heat;
    L.parts.emplace_back("heat", heat.item<double>());
    const int64_t np = static_cast<int64_t>(idx_n.size());
    if (np > 0) {
      auto opt = torch::TensorOptions().dtype(torch::kLong);
      auto r = raw.permute({0, 2, 3, 1});  // N h w D
      auto sel = r.index({torch::tensor(idx_n, opt), torch::tensor(idx_v, opt), torch::tensor(idx_u, opt)});
      auto reg = sel.index({Slice(), Slice(C_, C_ + kBoxCodeSize)});
      regressionLosses(reg, torch::from_blob(codes.data(), {np, kBoxCodeSize}).clone(), torch::tensor(vvalid), t,
                       &L.total, &L.parts);
    } else {
      L.parts.emplace_back("reg", 0.0);
      L.parts.emplace_back("vel", 0.0);
    }
    return L;
  }

  std::vector<Box> decode(const NetworkOutput& out, int sample, const BevGeometry& g,
                          const InferenceOptions& o) const override {
    const int stride = config_.center.stride;
    const auto& raw = out.head.at(stride)[sample];
    const int w = static_cast<int>(raw.size(2));
    auto heat = torch::sigmoid(raw.index({Slice(0, C_)}));
    // Peaks: local maxima of a 3x3 window (CenterNet), so one object gives one candidate.
    auto peak = F::max_pool2d(heat.unsqueeze(0), F::MaxPool2dFuncOptions(3).stride(1).padding(1)).squeeze(0);
    heat = heat * heat.eq(peak).to(torch::kFloat);
    auto reg = raw.index({Slice(C_, C_ + kBoxCodeSize)}).contiguous();
    auto ra = reg.accessor<float, 3>();
    std::vector<Box> boxes;
    for (int c = 0; c < C_; ++c) {
      auto sc = heat[c].reshape({-1});
      torch::Tensor keep, vals;
      if (!selectCandidates(sc, config_.classes[c], o, &keep, &vals)) continue;
      auto ka = keep.accessor<int64_t, 1>();
      auto va = vals.accessor<float, 1>();
      for (int64_t i = 0; i < keep.numel(); ++i) {
        const int v = static_cast<int>(ka[i] / w), u = static_cast<int>(ka[i] % w);
        BoxCode code;
        for (int k = 0; k < kBoxCodeSize; ++k) code[k] = ra[k][v][u];
        Box b = decodeCenterBox(code, u, v, stride, g, config_.sweep_interval);
        b.label = config_.classes[c];
        b.score = va[i];
        boxes.push_back(b);
      }
    }
    return boxes;
  }

 private:
  ModelConfig config_;
  int C_;
};

}  // namespace

std::unique_ptr<DetectionHead> makeHead(const ModelConfig& config, const std::vector<Anchor>& anchors) {
  if (config.head == HeadType::Anchor) return std::make_unique<AnchorHead>(config, anchors);
  return std::make_unique<CenterHead>(config);
}

}  // namespace nn
}  // namespace ret3d
