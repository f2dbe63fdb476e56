// `ret3d train intra`: trains IntraRM (Ret3D §3.2) on another detector's boxes, or prints a model's metadata.
//   ret3d train intra --data ../shared/data/kitti_tracking --detections ../shared/data/kitti_tracking/detections/pointrcnn
//                     --sequences 1-15 --config config/relation/intra_rm.yaml --out models/kitti_pointrcnn/intra_rm.pt
#include <filesystem>
#include <iostream>
#include <sstream>

#include "ret3d/core/log.h"
#include "ret3d/eval/eval_data.h"
#include "ret3d/relation/intra_rm.h"
#include "ret3d/train/intra_trainer.h"
#include "tools/train_command.h"

namespace ret3d {
namespace tools {
namespace {

using TrainIntraArgs = RelationTrainArgs;

int runTrainIntra(const TrainIntraArgs& a) {
  if (!a.inspect.empty()) return a.printModelInfo("IntraRM", relation::readIntraRMModelInfo(a.inspect));
  a.validate();
  relation::setTorchThreads(a.threads);
  auto opt = a.trainOptions<train::IntraTrainOptions>(relation::loadIntraRMConfig);

  std::vector<relation::IntraRMFrame> train_frames, val_frames;
  if (a.detector.given()) {
    // This package's detector on the scans: boxes with features, computed once and cached beside the model.
    auto load = [&](const std::string& list, const std::string& suffix) {
      return train::loadIntraFrames(a.data, a.detector.run(a.data, list, a.threads, a.out + ".dets", suffix),
                                    opt.config.train);
    };
    train_frames = load(a.sequences, "");
    if (!a.val_sequences.empty()) val_frames = load(a.val_sequences, ".val");
  } else {
    train::IntraDataOptions data;
    data.data_dir = a.data;
    data.detections_dir = a.detections;
    if (!a.sequences.empty()) data.sequences = eval::parseSequenceList(a.sequences);
    train_frames = train::loadIntraFrames(data, opt.config.train);
    if (!a.val_sequences.empty()) {
      data.sequences = eval::parseSequenceList(a.val_sequences);
      val_frames = train::loadIntraFrames(data, opt.config.train);
    }
  }
  std::size_t boxes = 0, pos = 0;
  for (const auto& f : train_frames) {
    boxes += f.detections.size();
    for (const auto& t : f.targets) pos += (t.cls[0] + t.cls[1] + t.cls[2]) > 0;
  }
  RET3D_INFO("IntraRM: " << train_frames.size() << " training frames (" << boxes << " detections, " << pos
                         << " positives), " << val_frames.size() << " validation frames");
  const train::IntraTrainReport r = train::trainIntraRM(train_frames, val_frames, opt);
  a.printSummary("IntraRM", r, !val_frames.empty());
  return 0;
}

TrainRegistrar reg = relationTrainer<TrainIntraArgs>(
    "intra", "IntraRM (Ret3D intra-frame relation module) on another detector's boxes",
    {"KITTI tracking (or object) root with labels and calibration",
     "detector outputs: KITTI object/tracking result files or per-class CSV folders",
     "IntraRM YAML config (default: built-in = config/relation/intra_rm.yaml)"},
    runTrainIntra);

}  // namespace
}  // namespace tools
}  // namespace ret3d
