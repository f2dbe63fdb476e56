// `ret3d train detector --data DIR... [--data-weights W...] [--labels-cover auto|all|camera...] --config YAML
//  --out MODEL [--resume] [--gt-database FILE]`: trains the LWD-3D base detector.
#include <fstream>
#include <iostream>
#include <sstream>

#include "ret3d/core/option_range.h"
#include "ret3d/core/yaml_reader.h"
#include "ret3d/train/detector_trainer.h"
#include "tools/train_command.h"

namespace ret3d {
namespace tools {
namespace {

CommandRun setup(CLI::App& app) {
  auto job = std::make_shared<DetectorTrainJob>();
  auto config = std::make_shared<std::string>();
  app.add_option("--data", job->data_dirs,
                 "KITTI folder(s) (ROOT or ROOT/training), used together; each in the tracking layout (label_02, "
                 "velodyne/SSSS/) or the object layout (label_2, velodyne/FFFFFF.bin), detected per folder")
      ->required()
      ->check(CLI::ExistingDirectory);
  app.add_option("--data-weights", job->data_weights,
                 "one weight per --data folder (or one for all; default 1): each frame of a folder is drawn WEIGHT "
                 "times per epoch on average (fractions: a seeded draw per epoch), e.g. --data sim real "
                 "--data-weights 1 4")
      ->check(CLI::NonNegativeNumber);
  auto covers = std::make_shared<std::vector<std::string>>();
  app.add_option("--labels-cover", *covers,
                 "where each --data folder's labels exist (one per folder, or one for all; default auto): all = all "
                 "around (simulator), camera = camera 2's view only (real KITTI; outside it no loss), auto = camera "
                 "when every object label has a 2D box in image 2, else all")
      ->check(CLI::IsMember({"auto", "all", "camera"}));
  app.add_option("--config", *config, "detector config YAML (config/detector/*.yaml)")
      ->required()
      ->check(CLI::ExistingFile);
  app.add_option("--out", job->out_model, "model file to write; checkpoints go beside it (<out>.ckpt*)")->required();
  app.add_flag("--resume", job->resume, "continue from <out>.ckpt when present");
  app.add_option("--init", job->init_model,
                 "start from this model's weights (same model config, or one that adds the IoU channels) with a fresh "
                 "optimiser and schedule; --resume still wins when <out>.ckpt exists")
      ->check(CLI::ExistingFile);
  app.add_flag("--init-other-cells", job->init_other_cells,
               "--init: the model file may have another cell size (model.bev.resolution); its weights are then only a "
               "starting point, e.g. for a coarser long-range grid");
  auto gt_database = std::make_shared<std::string>();
  app.add_option("--gt-database", *gt_database,
                 "ground-truth sampling database (`ret3d train gtdb`; overrides train.gt_database)")
      ->check(CLI::ExistingFile);
  auto threads = std::make_shared<int>(0);
  app.add_option("--threads", *threads, "torch threads (default: the config's train.threads, else inference.threads)")
      ->check(CLI::PositiveNumber);
  return [job, config, threads, covers, gt_database]() -> int {
    for (const std::string& c : *covers) job->label_cover.push_back(labelCoverFromName(c));
    job->config_text = readConfigText(*config, *config);  // a `base:` chain resolved, as stored in the model
    job->options = detectorOptionsFromYaml(job->config_text, *config);
    if (*threads > 0) job->options.train.threads = *threads;
    if (!gt_database->empty()) job->options.train.sensor_augment.gt_database = *gt_database;
    try {
      job->options.train.validate();
    } catch (const OptionError& e) {
      throw std::runtime_error("train detector: " + std::string(e.what()) + " (with the command line's overrides)");
    }
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
