#include "ret3d/relation/intra_rm_config.h"

#include <cmath>
#include <stdexcept>

#include "config_sections.h"

namespace ret3d {
namespace relation {

void IntraRMArch::validate() const {
  if (hidden < 1) throw std::invalid_argument("IntraRM model.hidden must be >= 1, got " + std::to_string(hidden));
  if (rounds < 1) throw std::invalid_argument("IntraRM model.rounds must be >= 1, got " + std::to_string(rounds));
  if (head_hidden < 1) throw std::invalid_argument("IntraRM model.head_hidden must be >= 1");
  if (!std::isfinite(radius) || radius < 0)
    throw std::invalid_argument("IntraRM model.radius must be a finite value >= 0 (metres)");
  if (feature_dim > 100000) throw std::invalid_argument("IntraRM model.feature_dim is implausibly large");
  for (std::size_t k = 0; k < 3; ++k) {
    if (!std::isfinite(score_scale[k]) || score_scale[k] <= 0)
      throw std::invalid_argument("IntraRM model.score_scale must be finite and > 0 (a monotone calibration)");
    if (!std::isfinite(score_bias[k])) throw std::invalid_argument("IntraRM model.score_bias must be finite");
  }
}

void IntraRMTrainConfig::validate() const {
  if (!(lr > 0)) throw std::invalid_argument("IntraRM train.lr must be > 0");
  if (weight_decay < 0) throw std::invalid_argument("IntraRM train.weight_decay must be >= 0");
  if (frames_per_batch < 1) throw std::invalid_argument("IntraRM train.frames_per_batch must be >= 1");
  if (epochs < 0) throw std::invalid_argument("IntraRM train.epochs must be >= 0");
  if (loc_weight < 0 || dir_weight < 0) throw std::invalid_argument("IntraRM loss weights must be >= 0");
  if (focal_alpha < 0 || focal_alpha > 1) throw std::invalid_argument("IntraRM train.focal_alpha must be in [0, 1]");
  if (focal_gamma < 0) throw std::invalid_argument("IntraRM train.focal_gamma must be >= 0");
  for (int k = 0; k < 3; ++k) {
    if (cls_pos_iou[k] <= 0 || cls_pos_iou[k] > 1 || reg_min_iou[k] <= 0 || reg_min_iou[k] > 1)
      throw std::invalid_argument("IntraRM IoU thresholds must be in (0, 1]");
  }
  if (augment_rotation < 0) throw std::invalid_argument("IntraRM train.augment_rotation must be >= 0");
}

// The keys, in the order toYaml writes them.
template <class ConfigIO>
void visitConfig(ConfigIO& io, IntraRMConfig* c) {
  IntraRMArch& m = c->model;
  io.section("model", "feature_dim", &m.feature_dim, "hidden", &m.hidden, "rounds", &m.rounds, "radius", &m.radius,
             "use_edges", &m.use_edges, "head_hidden", &m.head_hidden, "refine_boxes", &m.refine_boxes, "score_scale",
             &m.score_scale, "score_bias", &m.score_bias);
  IntraRMTrainConfig& t = c->train;
  io.section("train", "lr", &t.lr, "weight_decay", &t.weight_decay, "frames_per_batch", &t.frames_per_batch,
             "epochs", &t.epochs, "loc_weight", &t.loc_weight, "dir_weight", &t.dir_weight, "focal_alpha",
             &t.focal_alpha, "focal_gamma", &t.focal_gamma, "cls_pos_iou", &t.cls_pos_iou, "reg_min_iou",
             &t.reg_min_iou, "augment_flip", &t.augment_flip, "augment_rotation", &t.augment_rotation, "seed",
             &t.seed);
}

template std::string toYaml(const IntraRMConfig& config);

IntraRMConfig parseIntraRMConfig(const std::string& yaml_text, const std::string& source) {
  return detail::readConfig<IntraRMConfig>("IntraRM", yaml_text, source);
}

IntraRMConfig loadIntraRMConfig(const std::string& path) { return loadConfig(parseIntraRMConfig, "IntraRM", path); }

}  // namespace relation
}  // namespace ret3d
