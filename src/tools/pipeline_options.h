// What the commands that run the offline pipeline (`ret3d detect`, `bench`, `autolabel`, `draw`) share on the
// command line side of pipeline::OfflinePipeline (include/ret3d/pipeline/offline_pipeline.h).
#pragma once

#include <vector>

#include <CLI/CLI.hpp>

#include "ret3d/pipeline/offline_pipeline.h"

namespace ret3d {
namespace tools {

// The --grid-extent option of the commands that run the detector (x_min,x_max,y_min,y_max in metres).
void addGridExtentOption(CLI::App& app, std::vector<double>* extent);

// The --score-threshold option of the commands that run the pipeline (PipelineConfig::score_threshold).
void addScoreThresholdOption(CLI::App& app, double* threshold);

// `config` with the package folder, and the threshold the nodelets' parameter file gives the detector
// (nodeletParamsScoreThreshold), filled in when the pipeline needs them (pipeline::usesPackageDir). Only then: the
// look-up asks rospack, which complains on stderr when the package is not on ROS_PACKAGE_PATH.
pipeline::PipelineConfig withPackageDir(pipeline::PipelineConfig config);

}  // namespace tools
}  // namespace ret3d
