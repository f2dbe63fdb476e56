#include "ret3d/pipeline/score_threshold.h"

namespace ret3d {
namespace pipeline {

std::optional<float> chooseScoreThreshold(std::optional<double> pipeline_params, bool tracks,
                                          std::optional<double> explicit_value) {
  if (explicit_value) return static_cast<float>(*explicit_value);
  if (pipeline_params && tracks) return static_cast<float>(*pipeline_params);
  return std::nullopt;
}

}  // namespace pipeline
}  // namespace ret3d
