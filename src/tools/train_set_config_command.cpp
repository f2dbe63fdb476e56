// `ret3d train set-config --model IN --config YAML --out OUT`: the model file IN with the config it stores (whose
// inference options apply by default: thresholds, point refinement, score calibration) replaced by YAML's, the
// weights and the model part unchanged. For options fitted after training, e.g. a score calibration refitted with
// scripts/fit_score_calibration.py. Nothing is trained; the YAML's model part must describe IN's network.
#include <iostream>
#include <stdexcept>

#include "ret3d/core/yaml_reader.h"
#include "ret3d/detector/detector.h"
#include "ret3d/detector/model_file.h"
#include "tools/train_command.h"

namespace ret3d {
namespace tools {
namespace {

CommandRun setup(CLI::App& app) {
  auto model = std::make_shared<std::string>();
  auto config = std::make_shared<std::string>();
  auto out = std::make_shared<std::string>();
  app.add_option("--model", *model, "the model file, e.g. models/lwd3d/detector.pt")->required()->check(CLI::ExistingFile);
  app.add_option("--config", *config, "a detector YAML (config/detector/*.yaml; a `base:` chain is stored resolved) to store in it")
      ->required()
      ->check(CLI::ExistingFile);
  app.add_option("--out", *out, "the model file to write (may be --model itself)")->required();
  return [model, config, out]() -> int {
    const std::string text = readConfigText(*config, *config);  // a `base:` chain resolved, as train detector does
    ModelFileContents file = readModelFile(*model);
    const DetectorOptions given = detectorOptionsFromYaml(text, *config);
    const std::vector<std::string> diffs = checkModelMetadata(file.metadata, given.model);
    if (!diffs.empty()) throw std::runtime_error(*config + " describes another network than " + *model + ": " + diffs.front());
    file.metadata.trained_with = text;
    writeModelFile(*out, file.metadata, file.weights);
    const Detector detector(detectorOptionsForModel(*out));  // loads as the pipeline will
    std::cout << *out << ": " << *config << " stored; published from score "
              << detector.options().inference.describeScoreThresholds() << std::endl;
    return 0;
  };
}

TrainRegistrar reg("set-config",
                   "a model file with another stored config (inference options, score calibration); nothing trained",
                   setup);

}  // namespace
}  // namespace tools
}  // namespace ret3d
