// The detector's model file: metadata (format version, classes, BEV geometry, anchors, feature sizes, head type, the
// config it was trained with) followed by the weights, with a checksum. Layout:
//   "RET3DMDL" | uint32 format version | uint64 n | n bytes of YAML metadata | uint64 m | m bytes of weights
//   (a libtorch archive) | uint64 FNV-1a checksum of everything before it
// Reading refuses a truncated or corrupt file, and checkModelMetadata says how a file differs from a config.
#pragma once

#include <cstdint>
#include <stdexcept>
#include <string>
#include <vector>

#include "ret3d/detector/anchors.h"
#include "ret3d/detector/detector_options.h"

namespace ret3d {

constexpr std::uint32_t kModelFormatVersion = 1;

class ModelFileError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

struct ModelMetadata {
  std::uint32_t format_version = kModelFormatVersion;
  ModelConfig config;
  std::vector<Anchor> anchors;  // the anchor head's priors (empty for the centre head)
  int in_channels = 0;
  int feature_dim = 0;          // length of the per-object feature o_i
  int feature_stride = 0;       // stride of the map o_i is sampled from
  std::int64_t parameter_count = 0;
  std::string trained_with;     // the full YAML config of the training run (informative)
  std::string created;          // UTC time of saving
};

std::string metadataToYaml(const ModelMetadata& m);
ModelMetadata metadataFromYaml(const std::string& yaml, const std::string& origin);

struct ModelFileContents {
  ModelMetadata metadata;
  std::string weights;
};

void writeModelFile(const std::string& path, const ModelMetadata& metadata, const std::string& weights);
// Throws ModelFileError naming the file and the problem (not a model file, other format version, truncated,
// checksum mismatch, unreadable metadata).
ModelFileContents readModelFile(const std::string& path);
// Differences between a file's model and the configured one, one line each; empty when they match.
std::vector<std::string> checkModelMetadata(const ModelMetadata& file, const ModelConfig& expected);

// The detector's options for a model file: the config it was trained with (stored in the file), or the YAML file
// `config_yaml` when not empty (its model part must then match the file's), with the file as model_path. Throws
// ModelFileError / std::runtime_error saying what is wrong.
DetectorOptions detectorOptionsForModel(const std::string& model_path, const std::string& config_yaml = "");

}  // namespace ret3d
