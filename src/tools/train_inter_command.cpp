// `ret3d train inter`: trains InterRM (Ret3D §3.3) on tracked sequences built by running the tracker (optionally after
// IntraRM) over another detector's boxes with the real ego poses, or prints a model's metadata.
//   ret3d train inter --data ../shared/data/kitti_tracking --detections ../shared/data/kitti_tracking/detections/pointrcnn
//                     --intra-model models/kitti_pointrcnn/intra_rm.pt --sequences 1-15 --out models/kitti_pointrcnn/inter_rm.pt
#include <iostream>
#include <memory>
#include <sstream>

#include "ret3d/core/log.h"
#include "ret3d/eval/eval_data.h"
#include "ret3d/relation/inter_rm.h"
#include "ret3d/relation/intra_rm.h"
#include "ret3d/train/inter_trainer.h"
#include "ret3d/tracking/tracker_options.h"
#include "tools/train_command.h"

namespace ret3d {
namespace tools {
namespace {

struct TrainInterArgs : RelationTrainArgs {
  std::string intra_model, tracker_config;
};

int runTrainInter(const TrainInterArgs& a) {
  if (!a.inspect.empty()) return a.printModelInfo("InterRM", relation::readInterRMModelInfo(a.inspect));
  a.validate();
  relation::setTorchThreads(a.threads);
  auto opt = a.trainOptions<train::InterTrainOptions>(relation::loadInterRMConfig);

  train::InterDataOptions data;
  data.data_dir = a.data;
  data.detections_dir = a.detections;
  data.intra_model = a.intra_model;
  if (!a.tracker_config.empty()) data.tracker = loadTrackerOptions(a.tracker_config);
  // The tracker keeps as many boxes per track as InterRM reads (the InterRM nodelet keeps max_history too).
  if (data.tracker.history_length != opt.config.model.max_history) {
    RET3D_INFO("tracker history_length " << data.tracker.history_length << " -> " << opt.config.model.max_history
                                         << " (the InterRM config's max_history)");
    data.tracker.history_length = opt.config.model.max_history;
  }
  auto load = [&](const std::string& list, const std::string& suffix) {
    data.sequences = list.empty() ? std::vector<std::string>{} : eval::parseSequenceList(list);
    io::SequenceDetections own;  // this package's detector's boxes and features, when --detector is given
    if (a.detector.given()) {
      own = a.detector.run(a.data, list, a.threads, a.out + ".dets", suffix);
      data.detector_outputs = &own;
    }
    return train::loadInterSamples(data, opt.config.train);
  };
  const auto train_samples = load(a.sequences, "");
  std::vector<relation::InterRMSample> val_samples;
  if (!a.val_sequences.empty()) val_samples = load(a.val_sequences, ".val");
  double mean_len = 0;
  for (const auto& s : train_samples) mean_len += static_cast<double>(s.sequence.boxes.size());
  if (!train_samples.empty()) mean_len /= static_cast<double>(train_samples.size());
  RET3D_INFO("InterRM: " << train_samples.size() << " training sequences (mean length " << mean_len << "), "
                         << val_samples.size() << " validation sequences");
  const train::InterTrainReport r = train::trainInterRM(train_samples, val_samples, opt);
  a.printSummary("InterRM", r, !val_samples.empty(), r.initial_val_loss);
  return 0;
}

TrainRegistrar reg = relationTrainer<TrainInterArgs>(
    "inter", "InterRM (Ret3D inter-frame relation module) on tracked detections",
    {"KITTI tracking root with labels, calibration and poses (pose/ or oxts/)",
     "detector outputs: KITTI tracking result files or per-class CSV folders",
     "InterRM YAML config (default: built-in = config/relation/inter_rm.yaml)"},
    runTrainInter, [](CLI::App& app, TrainInterArgs& a) {
      app.add_option("--intra-model", a.intra_model, "IntraRM model run on each frame before tracking (optional)");
      app.add_option("--tracker-config", a.tracker_config, "tracker YAML (default: built-in = config/tracker.yaml)");
    });

}  // namespace
}  // namespace tools
}  // namespace ret3d
