#include "ret3d/relation/intra_rm_config.h"

#include <cmath>
#include <fstream>
#include <set>
#include <sstream>
#include <stdexcept>

#include <yaml-cpp/yaml.h>

#include "ret3d/core/types.h"

namespace ret3d {
namespace relation {

namespace {

[[noreturn]] void fail(const std::string& source, const std::string& what) {
  throw std::invalid_argument("IntraRM config " + source + ": " + what);
}

void checkKeys(const YAML::Node& node, const std::set<std::string>& allowed, const std::string& source,
               const std::string& section) {
  if (!node.IsMap()) fail(source, "'" + section + "' must be a mapping");
  for (const auto& kv : node) {
    const std::string key = kv.first.as<std::string>();
    if (!allowed.count(key)) {
      std::string list;
      for (const auto& a : allowed) list += (list.empty() ? "" : ", ") + a;
      fail(source, "unknown key '" + section + "." + key + "' (known: " + list + ")");
    }
  }
}

template <typename T>
void read(const YAML::Node& node, const char* key, T* value, const std::string& source, const std::string& section) {
  if (!node[key]) return;
  try {
    *value = node[key].as<T>();
  } catch (const YAML::Exception&) {
    fail(source, "'" + section + "." + key + "' (line " + std::to_string(node[key].Mark().line + 1) +
                     ") is not a valid value");
  }
}

void readPerClass(const YAML::Node& node, const char* key, PerClass* value, const std::string& source) {
  if (!node[key]) return;
  const YAML::Node n = node[key];
  if (!n.IsMap()) fail(source, std::string("'train.") + key + "' must map Car/Pedestrian/Cyclist to numbers");
  for (const auto& kv : n) {
    const std::string name = kv.first.as<std::string>();
    const auto cls = classFromName(name);
    if (!cls) fail(source, std::string("'train.") + key + "' has unknown class '" + name + "'");
    try {
      (*value)[static_cast<int>(*cls) - 1] = kv.second.as<double>();
    } catch (const YAML::Exception&) {
      fail(source, std::string("'train.") + key + "." + name + "' is not a number");
    }
  }
}

}  // namespace

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
  YAML::Node root;
  try {
    root = YAML::Load(yaml_text);
  } catch (const YAML::Exception& e) {
    fail(source, std::string("not valid YAML: ") + e.what());
  }
  IntraRMConfig c;
  if (root.IsNull()) return c;
  checkKeys(root, {"model", "train"}, source, "<top>");
  if (const YAML::Node m = root["model"]) {
    checkKeys(m, {"feature_dim", "hidden", "rounds", "radius", "use_edges", "head_hidden", "refine_boxes"}, source,
              "model");
    read(m, "feature_dim", &c.model.feature_dim, source, "model");
    read(m, "hidden", &c.model.hidden, source, "model");
    read(m, "rounds", &c.model.rounds, source, "model");
    read(m, "radius", &c.model.radius, source, "model");
    read(m, "use_edges", &c.model.use_edges, source, "model");
    read(m, "head_hidden", &c.model.head_hidden, source, "model");
    read(m, "refine_boxes", &c.model.refine_boxes, source, "model");
  }
  if (const YAML::Node t = root["train"]) {
    checkKeys(t,
              {"lr", "weight_decay", "frames_per_batch", "epochs", "loc_weight", "dir_weight", "focal_alpha",
               "focal_gamma", "cls_pos_iou", "reg_min_iou", "augment_flip", "augment_rotation", "seed"},
              source, "train");
    read(t, "lr", &c.train.lr, source, "train");
    read(t, "weight_decay", &c.train.weight_decay, source, "train");
    read(t, "frames_per_batch", &c.train.frames_per_batch, source, "train");
    read(t, "epochs", &c.train.epochs, source, "train");
    read(t, "loc_weight", &c.train.loc_weight, source, "train");
    read(t, "dir_weight", &c.train.dir_weight, source, "train");
    read(t, "focal_alpha", &c.train.focal_alpha, source, "train");
    read(t, "focal_gamma", &c.train.focal_gamma, source, "train");
    readPerClass(t, "cls_pos_iou", &c.train.cls_pos_iou, source);
    readPerClass(t, "reg_min_iou", &c.train.reg_min_iou, source);
    read(t, "augment_flip", &c.train.augment_flip, source, "train");
    read(t, "augment_rotation", &c.train.augment_rotation, source, "train");
    read(t, "seed", &c.train.seed, source, "train");
  }
  try {
    c.model.validate();
    c.train.validate();
  } catch (const std::invalid_argument& e) {
    fail(source, e.what());
  }
  return c;
}

IntraRMConfig loadIntraRMConfig(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw std::runtime_error("IntraRM config " + path + ": cannot open");
  std::stringstream ss;
  ss << in.rdbuf();
  return parseIntraRMConfig(ss.str(), path);
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
