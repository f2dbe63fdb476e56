#include "ret3d/relation/intra_rm_config.h"

#include <cmath>
#include <stdexcept>

#include <yaml-cpp/yaml.h>

#include "config_sections.h"

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
  return detail::readConfigSections<IntraRMConfig>(
      "IntraRM", yaml_text, source, [](YamlReader& m, YamlReader& t, IntraRMConfig* c) {
        m.get("feature_dim", &c->model.feature_dim);
        m.get("hidden", &c->model.hidden);
        m.get("rounds", &c->model.rounds);
        m.get("radius", &c->model.radius);
        m.get("use_edges", &c->model.use_edges);
        m.get("head_hidden", &c->model.head_hidden);
        m.get("refine_boxes", &c->model.refine_boxes);
        t.get("lr", &c->train.lr);
        t.get("weight_decay", &c->train.weight_decay);
        t.get("frames_per_batch", &c->train.frames_per_batch);
        t.get("epochs", &c->train.epochs);
        t.get("loc_weight", &c->train.loc_weight);
        t.get("dir_weight", &c->train.dir_weight);
        t.get("focal_alpha", &c->train.focal_alpha);
        t.get("focal_gamma", &c->train.focal_gamma);
        t.getPerClass("cls_pos_iou", &c->train.cls_pos_iou);
        t.getPerClass("reg_min_iou", &c->train.reg_min_iou);
        t.get("augment_flip", &c->train.augment_flip);
        t.get("augment_rotation", &c->train.augment_rotation);
        t.get("seed", &c->train.seed);
      });
}

IntraRMConfig loadIntraRMConfig(const std::string& path) {
  return parseIntraRMConfig(readConfigText(path, "IntraRM config " + path), path);
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
  auto per_class = [&](const char* key, const PerClass<double>& v) {
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
