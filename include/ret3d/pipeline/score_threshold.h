// Which detector score threshold wins: one function for the offline pipeline (`ret3d detect`, `bench`, `autolabel`,
// `draw`) and the detector nodelet (ros/params.cpp). Sources, lowest precedence first (docs/ARCHITECTURE.md,
// "Detector score threshold"):
//   1. the model file's inference.score_threshold and class_score_threshold (the config it was trained with, stored
//      in the file);
//   2. a detector config (--detector-config / ~config): its inference thresholds replace the model's
//      (both already in the InferenceOptions detectorOptionsForModel returns);
//   3. the pipeline's parameter file, config/ret3d.yaml's ret3d_detector/score_threshold: the score from which the
//      detector feeds the tracker. Online always (the launch file loads it as ~score_threshold); offline only when
//      the pipeline tracks (track or inter stage);
//   4. an explicit value: --score-threshold (offline), ~score_threshold set by a launch argument or the command
//      line (online, where it replaces 3 on the parameter server);
//   5. dynamic_reconfigure (cfg/Detector.cfg), online at run time only: the detector nodelet's callback.
#pragma once

#include <optional>

namespace ret3d {
namespace pipeline {

// The threshold every class starts with when a source above the model's (3 or 4 above) sets it, or nullopt: the
// model's or config's own (source 1 or 2), per class where it has class_score_threshold. `pipeline_params`: source 3
// as read (nullopt: no file or no key); `tracks`: the pipeline feeds a tracker; `explicit_value`: source 4. The caller
// applies a value with InferenceOptions::setScoreThreshold and checks the range (InferenceOptions::kScoreThreshold)
// where it reads each value, to name its source.
std::optional<float> chooseScoreThreshold(std::optional<double> pipeline_params, bool tracks,
                                          std::optional<double> explicit_value);

}  // namespace pipeline
}  // namespace ret3d
