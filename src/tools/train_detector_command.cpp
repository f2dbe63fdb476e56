// `ret3d train detector --data DIR --config YAML --out MODEL [--resume] [--gt-database FILE]`: trains the LWD-3D
// base detector.
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
  app.add_option("--data", job->data_dirs, "KITTI tracking-layout folder(s) (ROOT or ROOT/training), used together")
      ->required()
      ->check(CLI::ExistingDirectory);
  app.add_option("--config", *config, "detector config YAML (config/detector/*.yaml)")
      ->required()
      ->check(CLI::ExistingFile);
  app.add_option("--out", job->out_model, "model file to write; checkpoints go beside it (<out>.ckpt*)")->required();
  app.add_flag("--resume", job->resume, "continue from <out>.ckpt when present");
  app.add_option("--init", job->init_model,
                 "start from this model's weights (same model config, or one that adds the IoU channels) with a fresh "
                 "optimiser and schedule; --resume still wins when <out>.ckpt exists")
      ->check(CLI::ExistingFile);
  auto gt_database = std::make_shared<std::string>();
  app.add_option("--gt-database", *gt_database,
                 "ground-truth sampling database (`ret3d train gtdb`; overrides train.gt_database)")
      ->check(CLI::ExistingFile);
  auto threads = std::make_shared<int>(0);
  app.add_option("--threads", *threads, "torch threads (default: the config's train.threads, else inference.threads)")
      ->check(CLI::PositiveNumber);
  return [job, config, threads, gt_database]() -> int {
    std::ifstream in(*config);
    std::stringstream ss;
    ss << in.rdbuf();
    job->config_text = ss.str();
    job->options = detectorOptionsFromYaml(job->config_text, *config);
    if (*threads > 0) job->options.train.threads = *threads;
    if (!gt_database->empty()) job->options.train.sensor_augment.gt_database = *gt_database;
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
