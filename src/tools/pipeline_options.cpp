#include "tools/pipeline_options.h"

#include "ret3d/ros/params.h"

namespace ret3d {
namespace tools {

void addGridExtentOption(CLI::App& app, std::vector<double>* extent) {
  app.add_option("--grid-extent", *extent,
                 "run the detector over this grid, x_min,x_max,y_min,y_max in m (e.g. --grid-extent=-80,80,-48,48; "
                 "default: the model's); the cost grows with the area")
      ->delimiter(',')
      ->expected(4);
}

void addScoreThresholdOption(CLI::App& app, double* threshold) {
  app.add_option("--score-threshold", *threshold,
                 "the lowest score the detector publishes (default: with the track stage config/ret3d.yaml's, as the "
                 "nodelets feed their tracker; otherwise the model's)");
}

pipeline::PipelineConfig withPackageDir(pipeline::PipelineConfig config) {
  if (!pipeline::usesPackageDir(config)) return config;
  config.package_dir = packagePath();
  config.params_score_threshold = nodeletParamsScoreThreshold(config.package_dir);
  return config;
}

}  // namespace tools
}  // namespace ret3d
