#include "ret3d/relation/intra_rm_config.h"

#include <stdexcept>

#include "config_sections.h"

namespace ret3d {
namespace relation {

void IntraRMArch::validate() const {
  checkOption("hidden", hidden, kHidden);
  checkOption("rounds", rounds, kRounds);
  checkOption("head_hidden", head_hidden, kHeadHidden);
  checkOption("radius", radius, kRadius);
  checkOption("feature_dim", static_cast<double>(feature_dim), kFeatureDim);
  checkOptionPerClass("score_scale", score_scale, kScoreScale);
  checkOptionPerClass("score_bias", score_bias, kScoreBias);
}

void IntraRMTrainConfig::validate() const {
  checkOption("lr", lr, kLr);
  checkOption("weight_decay", weight_decay, kNonNegative);
  checkOption("frames_per_batch", frames_per_batch, kFramesPerBatch);
  checkOption("epochs", epochs, kNonNegative);
  checkOption("loc_weight", loc_weight, kNonNegative);
  checkOption("dir_weight", dir_weight, kNonNegative);
  checkOption("focal_alpha", focal_alpha, kFocalAlpha);
  checkOption("focal_gamma", focal_gamma, kNonNegative);
  checkOptionPerClass("cls_pos_iou", cls_pos_iou, kIou);
  checkOptionPerClass("reg_min_iou", reg_min_iou, kIou);
  checkOption("augment_rotation", augment_rotation, kNonNegative);
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
