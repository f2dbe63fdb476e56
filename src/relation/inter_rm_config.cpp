// InterRM configuration from YAML (config/relation/inter_rm.yaml): one loader, loud on typos.
#include <stdexcept>

#include "config_sections.h"

#include "ret3d/relation/inter_rm.h"

namespace ret3d {
namespace relation {

namespace {

const std::initializer_list<std::pair<const char*, InterPositionalEncoding>> kPositionalEncodings = {
    {"implicit", InterPositionalEncoding::Implicit},
    {"temporal", InterPositionalEncoding::Temporal},
    {"spatial", InterPositionalEncoding::Spatial}};

}  // namespace

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

// The keys, in the order toYaml writes them.
template <class ConfigIO>
void visitConfig(ConfigIO& io, InterRMConfig* c) {
  InterRMArch& m = c->model;
  const detail::Choice<InterPositionalEncoding> pe{&m.positional_encoding, kPositionalEncodings};
  io.section("model", "c_enc", &m.c_enc, "heads", &m.heads, "ffn_expansion", &m.ffn_expansion, "positional_encoding",
             pe, "max_history", &m.max_history, "regress_size", &m.regress_size);
  InterRMTrainConfig& t = c->train;
  io.section("train", "lr", &t.lr, "weight_decay", &t.weight_decay, "sequences_per_batch", &t.sequences_per_batch,
             "epochs", &t.epochs, "smooth_l1_beta", &t.smooth_l1_beta, "reg_min_iou", &t.reg_min_iou, "augment_flip",
             &t.augment_flip, "seed", &t.seed);
}

InterRMConfig parseInterRMConfig(const std::string& yaml_text, const std::string& source) {
  return detail::readConfig<InterRMConfig>("InterRM", yaml_text, source);
}

InterRMConfig loadInterRMConfig(const std::string& path) { return loadConfig(parseInterRMConfig, "InterRM", path); }

template std::string toYaml(const InterRMConfig& config);

const char* positionalEncodingName(InterPositionalEncoding pe) {
  for (const auto& [name, value] : kPositionalEncodings)
    if (value == pe) return name;
  return "?";
}

}  // namespace relation
}  // namespace ret3d
