// InterRM configuration from YAML (config/relation/inter_rm.yaml): one loader, loud on typos.
#include <stdexcept>

#include <yaml-cpp/yaml.h>

#include "config_sections.h"

#include "ret3d/relation/inter_rm.h"

namespace ret3d {
namespace relation {

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
  for (ObjectClass k : kDetectedClasses)
    if (!(reg_min_iou.at(k) > 0 && reg_min_iou.at(k) <= 1)) bad("reg_min_iou values must be in (0, 1]");
}

InterRMConfig parseInterRMConfig(const std::string& yaml_text, const std::string& source) {
  return detail::readConfigSections<InterRMConfig>(
      "InterRM", yaml_text, source, [](YamlReader& m, YamlReader& t, InterRMConfig* c) {
        m.get("regress_size", &c->model.regress_size);
        m.get("c_enc", &c->model.c_enc);
        m.get("heads", &c->model.heads);
        m.get("ffn_expansion", &c->model.ffn_expansion);
        m.getChoice("positional_encoding", &c->model.positional_encoding,
                    {{"implicit", InterPositionalEncoding::Implicit},
                     {"temporal", InterPositionalEncoding::Temporal},
                     {"spatial", InterPositionalEncoding::Spatial}});
        m.get("max_history", &c->model.max_history);
        t.get("lr", &c->train.lr);
        t.get("weight_decay", &c->train.weight_decay);
        t.get("sequences_per_batch", &c->train.sequences_per_batch);
        t.get("epochs", &c->train.epochs);
        t.get("smooth_l1_beta", &c->train.smooth_l1_beta);
        t.get("augment_flip", &c->train.augment_flip);
        t.get("seed", &c->train.seed);
        t.getPerClass("reg_min_iou", &c->train.reg_min_iou);
      });
}

InterRMConfig loadInterRMConfig(const std::string& path) {
  return parseInterRMConfig(readConfigText(path, "InterRM config " + path), path);
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
    e << YAML::Key << className(k) << YAML::Value << c.train.reg_min_iou.at(k);
  e << YAML::EndMap;
  e << YAML::Key << "augment_flip" << YAML::Value << c.train.augment_flip;
  e << YAML::Key << "seed" << YAML::Value << c.train.seed;
  e << YAML::EndMap;
  e << YAML::EndMap;
  return e.c_str();
}

}  // namespace relation
}  // namespace ret3d
