// Configuration of IntraRM (Ret3D §3.2): the network's shape (saved in every model file) and the training settings.
// Read from YAML (config/relation/intra_rm.yaml); an unknown key or a bad value fails loudly, naming it.
#pragma once

#include <cstddef>
#include <cstdint>
#include <limits>
#include <string>

#include "ret3d/core/option_range.h"
#include "ret3d/core/per_class.h"
#include "ret3d/relation/relation_module.h"

namespace ret3d {
namespace relation {

// What defines a trained network; stored in the model file and checked when it is loaded.
struct IntraRMArch {
  std::size_t feature_dim = 0;  // length of the detector feature o_i (eq. 1); 0 = basic features d_i alone
  int hidden = 64;              // C_x, the node feature length
  int rounds = 4;               // m, the message-passing rounds (eqs. (2)-(3) repeated)
  double radius = 2.0;          // r, metres: objects closer than this (BEV centres) are linked
  bool use_edges = true;        // false: self-loops only, each object refined alone (no-edge ablation)
  int head_hidden = 128;        // width of the head's hidden layer
  // false: refine() keeps the input box geometry and refines the class scores only (the regression heads are still
  // trained, eq. (5) unchanged). For a detector whose boxes come from its points (PointRCNN), box-level context
  // alone does not locate a box better than the detector did (docs/RESULTS.md, IntraRM).
  bool refine_boxes = true;
  // The published score of a box of class c is sigmoid(score_scale[c] * logit + score_bias[c]) of its class channel:
  // Platt scaling fitted after training (calibrateIntraRMScores), so that it is the probability that the box is a
  // true positive of its class, the scale a tracker's thresholds are set in. The focal loss the network learns by
  // (alpha 0.25, gamma 2) ranks boxes well but leaves the raw sigmoid of a true positive far below that probability,
  // unequally per class. Identity (1, 0) in a model without it.
  PerClass<double> score_scale{1.0, 1.0, 1.0};
  PerClass<double> score_bias{0.0, 0.0, 0.0};

  // Ranges (core/option_range.h), checked by validate() alone.
  static constexpr OptionRange kHidden{1, std::numeric_limits<double>::infinity()}, kRounds{1, std::numeric_limits<double>::infinity()}, kHeadHidden{1, std::numeric_limits<double>::infinity()};
  static constexpr OptionRange kRadius{0, OptionRange::kFinite};  // m
  static constexpr OptionRange kFeatureDim{0, 100000};
  static constexpr OptionRange kScoreScale{0, OptionRange::kFinite, true};  // a monotone calibration
  static constexpr OptionRange kScoreBias{-OptionRange::kFinite, OptionRange::kFinite};

  void validate() const;  // throws OptionError (a std::invalid_argument) naming the field
};

struct IntraRMTrainConfig {
  double lr = 3e-4;             // AdamW, as the paper
  double weight_decay = 0.01;
  int frames_per_batch = 16;
  int epochs = 30;
  double loc_weight = 2.0;      // lambda_1 of eq. (5)
  double dir_weight = 0.2;      // lambda_2 of eq. (5)
  double focal_alpha = 0.25;
  double focal_gamma = 2.0;
  // A detection is a positive of its class when its class-aware BEV IoU with a ground-truth box reaches this
  // (the KITTI 3D thresholds, so the refined score ranks boxes the benchmark counts as hits)...
  PerClass<double> cls_pos_iou{0.7, 0.5, 0.5};
  // ...and its box is regressed towards that ground truth when the IoU reaches this.
  PerClass<double> reg_min_iou{0.5, 0.3, 0.3};
  bool augment_flip = true;        // mirror y (and yaw) with probability 0.5
  double augment_rotation = 0.39;  // rotate a frame about the sensor's z axis by U(-a, a) radians
  std::uint64_t seed = 1;

  static constexpr OptionRange kLr{0, std::numeric_limits<double>::infinity(), true};
  static constexpr OptionRange kNonNegative{0, std::numeric_limits<double>::infinity()};  // weight_decay, epochs, loss weights, focal_gamma, rotation
  static constexpr OptionRange kFramesPerBatch{1, std::numeric_limits<double>::infinity()};
  static constexpr OptionRange kFocalAlpha{0, 1};
  static constexpr OptionRange kIou{0, 1, true};  // cls_pos_iou, reg_min_iou

  void validate() const;  // throws OptionError naming the field
};

using IntraRMConfig = RelationConfig<IntraRMArch, IntraRMTrainConfig>;

// Reads a YAML file with optional sections `model:` and `train:`; missing keys keep their defaults (toYaml writes it).
IntraRMConfig loadIntraRMConfig(const std::string& path);
// Parses YAML text (`source` names it in error messages).
IntraRMConfig parseIntraRMConfig(const std::string& yaml_text, const std::string& source = "<string>");

}  // namespace relation
}  // namespace ret3d
