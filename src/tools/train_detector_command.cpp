// `ret3d train detector --data DIR --config YAML --out MODEL [--resume]`: trains the LWD-3D base detector.
#include <fstream>
#include <iostream>
#include <sstream>

#include "ret3d/train/detector_trainer.h"
#include "tools/train_command.h"

namespace ret3d {
namespace tools {
namespace {

CommandRun setup(CLI::App& app) {
  auto job = std::make_shared<DetectorTrainJob>();
  auto config = std::make_shared<std::string>();
  app.add_option("--data", job->data_dir, "KITTI tracking-layout folder (ROOT or ROOT/training)")
      ->required()
      ->check(CLI::ExistingDirectory);
  app.add_option("--config", *config, "detector config YAML (config/detector/*.yaml)")
      ->required()
      ->check(CLI::ExistingFile);
  app.add_option("--out", job->out_model, "model file to write; checkpoints go beside it (<out>.ckpt*)")->required();
  app.add_flag("--resume", job->resume, "continue from <out>.ckpt when present");
  return [job, config]() -> int {
    std::ifstream in(*config);
    std::stringstream ss;
    ss << in.rdbuf();
    job->config_text = ss.str();
    job->options = detectorOptionsFromYaml(job->config_text, *config);
    const DetectorTrainResult r = trainDetector(*job);
    std::cout << "trained " << r.steps << " steps in " << r.seconds << " s, last epoch loss " << r.last_loss
              << ", model " << job->out_model << std::endl;
    return 0;
  };
}

TrainRegistrar reg("detector", "the LWD-3D base detector (BEV, network, anchor or centre head)", setup);

}  // namespace
}  // namespace tools
}  // namespace ret3d
