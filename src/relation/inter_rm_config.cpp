// InterRM configuration from YAML (config/relation/inter_rm.yaml): one loader, loud on typos.
#include <fstream>
#include <set>
#include <sstream>
#include <stdexcept>

#include <yaml-cpp/yaml.h>

#include "ret3d/relation/inter_rm.h"

namespace ret3d {
namespace relation {

namespace {

[[noreturn]] void fail(const std::string& source, const std::string& what) {
  throw std::invalid_argument("InterRM config " + source + ": " + what);
}

void checkKeys(const YAML::Node& node, const std::set<std::string>& allowed, const std::string& source,
               const std::string& section) {
  if (!node.IsMap()) fail(source, "'" + section + "' must be a mapping");
  for (const auto& kv : node) {
    const std::string key = kv.first.as<std::string>();
    if (!allowed.count(key)) {
      std::string list;
      for (const auto& a : allowed) list += (list.empty() ? "" : ", ") + a;
      fail(source, "unknown key '" + section + "." + key + "' (line " + std::to_string(kv.first.Mark().line + 1) +
                       "; known: " + list + ")");
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

InterPositionalEncoding parsePe(const std::string& s, const std::string& source) {
  if (s == "implicit") return InterPositionalEncoding::Implicit;
  if (s == "temporal") return InterPositionalEncoding::Temporal;
  if (s == "spatial") return InterPositionalEncoding::Spatial;
  fail(source, "'model.positional_encoding' is '" + s + "' (allowed: implicit, temporal, spatial)");
}

}  // namespace

const char* positionalEncodingName(InterPositionalEncoding pe) {
  switch (pe) {
    case InterPositionalEncoding::Implicit: return "implicit";
    case InterPositionalEncoding::Temporal: return "temporal";
    case InterPositionalEncoding::Spatial: return "spatial";
  }
  return "?";
}

void InterRMArch::validate() const {
  auto bad = [](const std::string& m) { throw std::invalid_argument("InterRM model: " + m); };
  if (c_enc < 4 || c_enc > 4096) bad("c_enc " + std::to_string(c_enc) + " is outside [4, 4096]");
  if (c_enc % 4 != 0) bad("c_enc " + std::to_string(c_enc) + " must be a multiple of 4 (sinusoidal encodings)");
  if (heads < 1 || c_enc % heads != 0)
    bad("heads " + std::to_string(heads) + " must be >= 1 and divide c_enc " + std::to_string(c_enc));
  if (ffn_expansion < 1 || ffn_expansion > 16) bad("ffn_expansion " + std::to_string(ffn_expansion) + " not in [1, 16]");
  if (max_history < 1 || max_history > 10000) bad("max_history " + std::to_string(max_history) + " not in [1, 10000]");
}

void InterRMTrainConfig::validate() const {
  auto bad = [](const std::string& m) { throw std::invalid_argument("InterRM train: " + m); };
  if (!(lr > 0)) bad("lr must be > 0");
  if (!(weight_decay >= 0)) bad("weight_decay must be >= 0");
  if (sequences_per_batch < 1) bad("sequences_per_batch must be >= 1");
  if (epochs < 0) bad("epochs must be >= 0");
  if (!(smooth_l1_beta > 0)) bad("smooth_l1_beta must be > 0");
  for (double v : reg_min_iou)
    if (!(v > 0 && v <= 1)) bad("reg_min_iou values must be in (0, 1]");
}

InterRMConfig parseInterRMConfig(const std::string& yaml_text, const std::string& source) {
  YAML::Node root;
  try {
    root = YAML::Load(yaml_text);
  } catch (const YAML::Exception& e) {
    throw std::runtime_error("InterRM config " + source + ": not valid YAML: " + e.what());
  }
  InterRMConfig c;
  if (root.IsNull()) return c;
  checkKeys(root, {"model", "train"}, source, "<top>");
  if (const YAML::Node m = root["model"]) {
    checkKeys(m, {"c_enc", "heads", "ffn_expansion", "positional_encoding", "max_history", "regress_size"}, source,
              "model");
    read(m, "regress_size", &c.model.regress_size, source, "model");
    read(m, "c_enc", &c.model.c_enc, source, "model");
    read(m, "heads", &c.model.heads, source, "model");
    read(m, "ffn_expansion", &c.model.ffn_expansion, source, "model");
    std::string pe = positionalEncodingName(c.model.positional_encoding);
    read(m, "positional_encoding", &pe, source, "model");
    c.model.positional_encoding = parsePe(pe, source);
    read(m, "max_history", &c.model.max_history, source, "model");
  }
  if (const YAML::Node t = root["train"]) {
    checkKeys(t,
              {"lr", "weight_decay", "sequences_per_batch", "epochs", "smooth_l1_beta", "reg_min_iou", "augment_flip",
               "seed"},
              source, "train");
    read(t, "lr", &c.train.lr, source, "train");
    read(t, "weight_decay", &c.train.weight_decay, source, "train");
    read(t, "sequences_per_batch", &c.train.sequences_per_batch, source, "train");
    read(t, "epochs", &c.train.epochs, source, "train");
    read(t, "smooth_l1_beta", &c.train.smooth_l1_beta, source, "train");
    read(t, "augment_flip", &c.train.augment_flip, source, "train");
    read(t, "seed", &c.train.seed, source, "train");
    if (const YAML::Node r = t["reg_min_iou"]) {
      if (!r.IsMap()) fail(source, "'train.reg_min_iou' must map Car/Pedestrian/Cyclist to numbers");
      for (const auto& kv : r) {
        const std::string name = kv.first.as<std::string>();
        const auto cls = classFromName(name);
        if (!cls) fail(source, "'train.reg_min_iou' has unknown class '" + name + "'");
        try {
          c.train.reg_min_iou[static_cast<int>(*cls) - 1] = kv.second.as<double>();
        } catch (const YAML::Exception&) {
          fail(source, "'train.reg_min_iou." + name + "' is not a number");
        }
      }
    }
  }
  try {
    c.model.validate();
    c.train.validate();
  } catch (const std::invalid_argument& e) {
    fail(source, e.what());
  }
  return c;
}

InterRMConfig loadInterRMConfig(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw std::runtime_error("InterRM config " + path + ": cannot be read");
  std::stringstream ss;
  ss << in.rdbuf();
  return parseInterRMConfig(ss.str(), path);
}

std::string toYaml(const InterRMConfig& c) {
  YAML::Emitter e;
  e << YAML::BeginMap;
  e << YAML::Key << "model" << YAML::Value << YAML::BeginMap;
  e << YAML::Key << "c_enc" << YAML::Value << c.model.c_enc;
  e << YAML::Key << "heads" << YAML::Value << c.model.heads;
  e << YAML::Key << "ffn_expansion" << YAML::Value << c.model.ffn_expansion;
  e << YAML::Key << "positional_encoding" << YAML::Value << positionalEncodingName(c.model.positional_encoding);
  e << YAML::Key << "max_history" << YAML::Value << c.model.max_history;
  e << YAML::Key << "regress_size" << YAML::Value << c.model.regress_size;
  e << YAML::EndMap;
  e << YAML::Key << "train" << YAML::Value << YAML::BeginMap;
  e << YAML::Key << "lr" << YAML::Value << c.train.lr;
  e << YAML::Key << "weight_decay" << YAML::Value << c.train.weight_decay;
  e << YAML::Key << "sequences_per_batch" << YAML::Value << c.train.sequences_per_batch;
  e << YAML::Key << "epochs" << YAML::Value << c.train.epochs;
  e << YAML::Key << "smooth_l1_beta" << YAML::Value << c.train.smooth_l1_beta;
  e << YAML::Key << "reg_min_iou" << YAML::Value << YAML::BeginMap;
  for (ObjectClass k : kDetectedClasses)
    e << YAML::Key << className(k) << YAML::Value << c.train.reg_min_iou[static_cast<int>(k) - 1];
  e << YAML::EndMap;
  e << YAML::Key << "augment_flip" << YAML::Value << c.train.augment_flip;
  e << YAML::Key << "seed" << YAML::Value << c.train.seed;
  e << YAML::EndMap;
  e << YAML::EndMap;
  return e.c_str();
}

}  // namespace relation
}  // namespace ret3d
