#include "ret3d/pipeline/score_threshold.h"

namespace ret3d {
namespace pipeline {

float chooseScoreThreshold(float model_or_config, std::optional<double> pipeline_params, bool tracks,
                           std::optional<double> explicit_value) {
  if (explicit_value) return static_cast<float>(*explicit_value);
  if (pipeline_params && tracks) return static_cast<float>(*pipeline_params);
  return model_or_config;
}

}  // namespace pipeline
}  // namespace ret3d
