#include "ret3d/relation/intra_rm_config.h"

#include <cmath>
#include <fstream>
#include <set>
#include <sstream>
#include <stdexcept>

#include <yaml-cpp/yaml.h>

#include "config_reader.h"

#include "ret3d/core/types.h"

namespace ret3d {
namespace relation {

void IntraRMArch::validate() const {
  if (hidden < 1) throw std::invalid_argument("IntraRM model.hidden must be >= 1, got " + std::to_string(hidden));
  if (rounds < 1) throw std::invalid_argument("IntraRM model.rounds must be >= 1, got " + std::to_string(rounds));
  if (head_hidden < 1) throw std::invalid_argument("IntraRM model.head_hidden must be >= 1");
  if (!std::isfinite(radius) || radius < 0)
    throw std::invalid_argument("IntraRM model.radius must be a finite value >= 0 (metres)");
  if (feature_dim > 100000) throw std::invalid_argument("IntraRM model.feature_dim is implausibly large");
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

IntraRMConfig parseIntraRMConfig(const std::string& yaml_text, const std::string& source) {
  const detail::ConfigReader r("IntraRM", source);
  const YAML::Node root = r.load(yaml_text);
  IntraRMConfig c;
  if (root.IsNull()) return c;
  r.checkKeys(root, {"model", "train"}, "<top>");
  if (const YAML::Node m = root["model"]) {
    r.checkKeys(m, {"feature_dim", "hidden", "rounds", "radius", "use_edges", "head_hidden", "refine_boxes"}, "model");
    r.read(m, "feature_dim", &c.model.feature_dim, "model");
    r.read(m, "hidden", &c.model.hidden, "model");
    r.read(m, "rounds", &c.model.rounds, "model");
    r.read(m, "radius", &c.model.radius, "model");
    r.read(m, "use_edges", &c.model.use_edges, "model");
    r.read(m, "head_hidden", &c.model.head_hidden, "model");
    r.read(m, "refine_boxes", &c.model.refine_boxes, "model");
  }
  if (const YAML::Node t = root["train"]) {
    r.checkKeys(t,
              {"lr", "weight_decay", "frames_per_batch", "epochs", "loc_weight", "dir_weight", "focal_alpha",
               "focal_gamma", "cls_pos_iou", "reg_min_iou", "augment_flip", "augment_rotation", "seed"}, "train");
    r.read(t, "lr", &c.train.lr, "train");
    r.read(t, "weight_decay", &c.train.weight_decay, "train");
    r.read(t, "frames_per_batch", &c.train.frames_per_batch, "train");
    r.read(t, "epochs", &c.train.epochs, "train");
    r.read(t, "loc_weight", &c.train.loc_weight, "train");
    r.read(t, "dir_weight", &c.train.dir_weight, "train");
    r.read(t, "focal_alpha", &c.train.focal_alpha, "train");
    r.read(t, "focal_gamma", &c.train.focal_gamma, "train");
    r.readPerClass(t, "cls_pos_iou", &c.train.cls_pos_iou, "train");
    r.readPerClass(t, "reg_min_iou", &c.train.reg_min_iou, "train");
    r.read(t, "augment_flip", &c.train.augment_flip, "train");
    r.read(t, "augment_rotation", &c.train.augment_rotation, "train");
    r.read(t, "seed", &c.train.seed, "train");
  }
  try {
    c.model.validate();
    c.train.validate();
  } catch (const std::invalid_argument& e) {
    r.fail(e.what());
  }
  return c;
}

IntraRMConfig loadIntraRMConfig(const std::string& path) {
  return parseIntraRMConfig(detail::readConfigFile("IntraRM", path), path);
}

std::string toYaml(const IntraRMConfig& c) {
  YAML::Emitter e;
  e << YAML::BeginMap;
  e << YAML::Key << "model" << YAML::Value << YAML::BeginMap;
  e << YAML::Key << "feature_dim" << YAML::Value << c.model.feature_dim;
  e << YAML::Key << "hidden" << YAML::Value << c.model.hidden;
  e << YAML::Key << "rounds" << YAML::Value << c.model.rounds;
  e << YAML::Key << "radius" << YAML::Value << c.model.radius;
  e << YAML::Key << "use_edges" << YAML::Value << c.model.use_edges;
  e << YAML::Key << "head_hidden" << YAML::Value << c.model.head_hidden;
  e << YAML::Key << "refine_boxes" << YAML::Value << c.model.refine_boxes;
  e << YAML::EndMap;
  auto per_class = [&](const char* key, const PerClass& v) {
    e << YAML::Key << key << YAML::Value << YAML::Flow << YAML::BeginMap;
    for (int k = 0; k < 3; ++k) e << YAML::Key << className(kDetectedClasses[k]) << YAML::Value << v[k];
    e << YAML::EndMap;
  };
  e << YAML::Key << "train" << YAML::Value << YAML::BeginMap;
  e << YAML::Key << "lr" << YAML::Value << c.train.lr;
  e << YAML::Key << "weight_decay" << YAML::Value << c.train.weight_decay;
  e << YAML::Key << "frames_per_batch" << YAML::Value << c.train.frames_per_batch;
  e << YAML::Key << "epochs" << YAML::Value << c.train.epochs;
  e << YAML::Key << "loc_weight" << YAML::Value << c.train.loc_weight;
  e << YAML::Key << "dir_weight" << YAML::Value << c.train.dir_weight;
  e << YAML::Key << "focal_alpha" << YAML::Value << c.train.focal_alpha;
  e << YAML::Key << "focal_gamma" << YAML::Value << c.train.focal_gamma;
  per_class("cls_pos_iou", c.train.cls_pos_iou);
  per_class("reg_min_iou", c.train.reg_min_iou);
  e << YAML::Key << "augment_flip" << YAML::Value << c.train.augment_flip;
  e << YAML::Key << "augment_rotation" << YAML::Value << c.train.augment_rotation;
  e << YAML::Key << "seed" << YAML::Value << c.train.seed;
  e << YAML::EndMap;
  e << YAML::EndMap;
  return e.c_str();
}

}  // namespace relation
}  // namespace ret3d
