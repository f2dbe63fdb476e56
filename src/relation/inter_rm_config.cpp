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
  checkOption("c_enc", c_enc, kCEnc);
  if (c_enc % 4 != 0)
    throw OptionError("c_enc", std::to_string(c_enc), "must be a multiple of 4 (sinusoidal encodings)");
  checkOption("heads", heads, kHeads);
  if (c_enc % heads != 0)
    throw OptionError("heads", std::to_string(heads), "must divide c_enc " + std::to_string(c_enc));
  checkOption("ffn_expansion", ffn_expansion, kFfnExpansion);
  checkOption("max_history", max_history, kMaxHistory);
}

void InterRMTrainConfig::validate() const {
  checkOption("lr", lr, kLr);
  checkOption("weight_decay", weight_decay, kNonNegative);
  checkOption("sequences_per_batch", sequences_per_batch, kSequencesPerBatch);
  checkOption("epochs", epochs, kNonNegative);
  checkOption("smooth_l1_beta", smooth_l1_beta, kSmoothL1Beta);
  checkOptionPerClass("reg_min_iou", reg_min_iou, kIou);
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
