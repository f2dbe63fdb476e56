#include "ret3d/train/inter_trainer.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <limits>
#include <map>
#include <numeric>
#include <random>
#include <sstream>
#include <stdexcept>

#include "ret3d/core/log.h"
#include "ret3d/core/progress.h"
#include "ret3d/io/detections.h"
#include "ret3d/io/kitti.h"
#include "ret3d/pipeline/track_histories.h"
#include "ret3d/relation/intra_rm.h"
#include "ret3d/relation/intra_rm_targets.h"
#include "ret3d/tracking/greedy_tracker.h"

#include "epoch_loop.h"

namespace ret3d {
namespace train {

using relation::InterRMSample;

std::vector<InterRMSample> loadInterSamples(const InterDataOptions& data, const relation::InterRMTrainConfig& config) {
  namespace fs = std::filesystem;
  const bool from_files = data.detector_outputs == nullptr;
  const io::DetectionLayout layout =
      from_files ? io::detectDetectionLayout(data.detections_dir) : io::DetectionLayout::KittiTracking;
  if (layout == io::DetectionLayout::KittiObject)
    throw std::runtime_error("detections " + data.detections_dir +
                             " are per-frame object result files; InterRM needs sequences (tracking result files or "
                             "per-class CSV folders)");
  kitti::TrackingDataset ds(data.data_dir);
  std::vector<std::string> seqs = data.sequences;
  if (seqs.empty())
    for (const std::string& s : ds.sequences())
      if (ds.hasLabels(s)) seqs.push_back(s);
  std::unique_ptr<relation::IntraRM> intra;
  if (!data.intra_model.empty()) {
    relation::IntraRMOptions o;
    o.model_path = data.intra_model;
    intra = std::make_unique<relation::IntraRM>(o);
  }
  // Targets as IntraRM assigns them (class-aware best BEV IoU, regressed from reg_min_iou).
  relation::IntraRMTrainConfig assign;
  assign.reg_min_iou = config.reg_min_iou;
  assign.cls_pos_iou = config.reg_min_iou;

  std::vector<InterRMSample> samples;
  for (const std::string& seq : seqs) {
    if (!ds.hasLabels(seq)) throw std::runtime_error("sequence " + seq + ": no labels in " + ds.dir());
    const auto poses = ds.lidarPoses(seq);
    if (poses.empty())
      throw std::runtime_error("sequence " + seq + ": no ego poses (" + ds.posePath(seq) + " or " + ds.oxtsPath(seq) +
                               ") - the tracker needs them");
    const kitti::Calibration calib = kitti::readCalibration(ds.calibPath(seq));
    std::map<int, relation::FrameGroundTruth> gt;
    for (const kitti::Label& l : kitti::readTrackingLabels(ds.labelPath(seq)))
      if (classFromName(l.type)) gt[l.frame].boxes.push_back(kitti::labelToBox(l, calib));
    // Per frame: another detector's result files, or this package's detector's outputs (boxes with features).
    std::map<int, Detections> dets;
    if (from_files) {
      for (const auto& [frame, labels] : io::readSequenceDetections(data.detections_dir, layout, seq))
        for (const kitti::Label& l : labels)
          if (classFromName(l.type)) dets[frame].boxes.push_back(kitti::labelToBox(l, calib));
    } else if (const auto it = data.detector_outputs->find(seq); it != data.detector_outputs->end()) {
      dets = it->second;
    }
    int last = static_cast<int>(poses.size()) - 1;
    if (!dets.empty() && dets.rbegin()->first > last)
      throw std::runtime_error("sequence " + seq + ": detections up to frame " + std::to_string(dets.rbegin()->first) +
                               " but only " + std::to_string(poses.size()) + " poses");
    GreedyTracker tracker(data.tracker);
    pipeline::TrackHistories histories(static_cast<std::size_t>(data.tracker.history_length), data.tracker.max_age);
    for (int f = 0; f <= last; ++f) {
      Detections d;
      if (auto it = dets.find(f); it != dets.end()) d = it->second;
      if (intra && !d.empty()) d = intra->refine(d);
      const double stamp = f * data.frame_period;
      const Eigen::Isometry3d& pose = poses[static_cast<std::size_t>(f)];
      const std::vector<Box> tracked = tracker.update(d.boxes, stamp, pose);
      pipeline::TrackHistories::Sequences sequences = histories.update(tracked, stamp, pose);
      if (tracked.empty()) continue;
      const auto g = gt.find(f);
      if (g == gt.end()) continue;
      const auto targets = relation::assignIntraRMTargets(tracked, g->second, assign);
      for (std::size_t k = 0; k < sequences.rows.size(); ++k) {
        const std::size_t i = sequences.rows[k];
        const relation::IntraRMTarget& t = targets[i];
        if (!t.regress) continue;
        InterRMSample s;
        s.sequence = std::move(sequences.sequences[k]);
        Box target = tracked[i];
        target.x += t.dx, target.y += t.dy, target.z += t.dz;
        target.length *= std::exp(t.dl), target.width *= std::exp(t.dw), target.height *= std::exp(t.dh);
        target.yaw += t.dyaw;
        s.target = target;
        samples.push_back(std::move(s));
      }
    }
  }
  return samples;
}

InterTrainReport trainInterRM(const std::vector<InterRMSample>& train, const std::vector<InterRMSample>& val,
                              const InterTrainOptions& options) {
  if (train.empty()) throw std::runtime_error("InterRM training: no training sequences");
  InterTrainReport report;
  report.train_sequences = train.size();
  report.val_sequences = val.size();
  // The untrained module is the identity: its loss is that of the input boxes, the bar to beat.
  const auto identity_loss = [&](relation::InterRMLearner& learner, int start_epoch, double* best_val) {
    if (val.empty() || start_epoch > 0) return;
    const relation::InterRMLoss V0 = learner.evaluate(val);
    report.initial_val_loss = V0.total;
    *best_val = report.initial_val_loss;
    // Written now, so that if no epoch beats the input boxes the model file is the identity, never a worse module.
    learner.model().save(options.out_path);
    report.best_epoch = 0;
    RET3D_INFO("InterRM: validation loss of the input boxes (identity) " << V0.total << " " << V0);
  };
  trainRelationModule<relation::InterRMLearner>("InterRM", options, options.config.train.sequences_per_batch, train,
                                                val, &report, identity_loss);
  if (!val.empty() && report.best_epoch == 0) {
    RET3D_WARN("InterRM: no epoch improved on the input boxes' validation loss; " << options.out_path
                                                                                  << " is the identity module");
  }
  return report;
}

}  // namespace train
}  // namespace ret3d
