#include "ret3d/train/intra_trainer.h"

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

#include "epoch_loop.h"

namespace ret3d {
namespace train {

using relation::IntraRMFrame;

namespace {

// The KITTI devkit ignores an unmatched detection whose image box lies more than half inside a DontCare region.
bool inDontCare(const kitti::Label& det, const std::vector<kitti::Label>& dont_care) {
  const double w = det.bbox[2] - det.bbox[0], h = det.bbox[3] - det.bbox[1];
  if (w <= 0 || h <= 0) return false;
  for (const kitti::Label& d : dont_care) {
    const double iw = std::min(det.bbox[2], d.bbox[2]) - std::max(det.bbox[0], d.bbox[0]);
    const double ih = std::min(det.bbox[3], d.bbox[3]) - std::max(det.bbox[1], d.bbox[1]);
    if (iw > 0 && ih > 0 && iw * ih / (w * h) > 0.5) return true;
  }
  return false;
}

// The ground truth of one frame: the three classes, and Van / Person_sitting / Person as "similar" (ignored).
relation::FrameGroundTruth groundTruth(const std::vector<kitti::Label>& gt_labels, const kitti::Calibration& calib,
                                       std::vector<kitti::Label>* dont_care) {
  relation::FrameGroundTruth gt;
  for (const kitti::Label& l : gt_labels) {
    if (l.type == "DontCare") {
      if (dont_care) dont_care->push_back(l);
    } else if (classFromName(l.type)) {
      gt.boxes.push_back(kitti::labelToBox(l, calib));
    } else if (l.type == "Van" || l.type == "Person_sitting" || l.type == "Person") {
      Box b = kitti::labelToBox(l, calib);
      b.label = l.type == "Van" ? ObjectClass::Car : ObjectClass::Pedestrian;
      gt.similar.push_back(b);
    }
  }
  return gt;
}

IntraRMFrame makeFrame(const std::vector<kitti::Label>& dets, const std::vector<kitti::Label>& gt_labels,
                       const kitti::Calibration& calib, const relation::IntraRMTrainConfig& config) {
  std::vector<kitti::Label> dont_care;
  const relation::FrameGroundTruth gt = groundTruth(gt_labels, calib, &dont_care);
  IntraRMFrame f;
  std::vector<bool> ignore;
  for (const kitti::Label& d : dets) {
    if (!classFromName(d.type)) continue;
    f.detections.boxes.push_back(kitti::labelToBox(d, calib));
    ignore.push_back(inDontCare(d, dont_care));
  }
  f.targets = relation::assignIntraRMTargets(f.detections.boxes, gt, config, ignore);
  return f;
}

}  // namespace

std::vector<IntraRMFrame> loadIntraFrames(const IntraDataOptions& data, const relation::IntraRMTrainConfig& config) {
  namespace fs = std::filesystem;
  std::vector<IntraRMFrame> frames;
  const io::DetectionLayout layout = io::detectDetectionLayout(data.detections_dir);
  const std::string root = data.data_dir;
  const bool tracking = fs::is_directory(root + "/training/label_02") || fs::is_directory(root + "/label_02");
  if (tracking) {
    if (layout == io::DetectionLayout::KittiObject)
      throw std::runtime_error("detections " + data.detections_dir +
                               " are per-frame object result files, but " + root + " is a tracking dataset");
    kitti::TrackingDataset ds(root);
    std::vector<std::string> seqs = data.sequences;
    if (seqs.empty()) {
      for (const std::string& s : ds.sequences())
        if (ds.hasLabels(s)) seqs.push_back(s);
    }
    for (const std::string& seq : seqs) {
      if (!ds.hasLabels(seq)) throw std::runtime_error("sequence " + seq + ": no labels in " + ds.dir());
      const kitti::Calibration calib = kitti::readCalibration(ds.calibPath(seq));
      std::map<int, std::vector<kitti::Label>> gt;
      for (kitti::Label& l : kitti::readTrackingLabels(ds.labelPath(seq))) gt[l.frame].push_back(std::move(l));
      const auto dets = io::readSequenceDetections(data.detections_dir, layout, seq);
      for (const auto& [frame, labels] : dets) {
        auto it = gt.find(frame);
        IntraRMFrame f = makeFrame(labels, it == gt.end() ? std::vector<kitti::Label>{} : it->second, calib, config);
        if (!f.detections.empty()) frames.push_back(std::move(f));
      }
    }
  } else {
    if (layout != io::DetectionLayout::KittiObject)
      throw std::runtime_error("detections " + data.detections_dir + " are " + io::layoutName(layout) +
                               " files, but " + root + " is an object dataset (label_2): use per-frame result files");
    kitti::ObjectDataset ds(root);
    for (const std::string& fr : ds.frames()) {
      if (!fs::exists(ds.labelPath(fr))) continue;
      const auto dets = io::readFrameDetections(data.detections_dir, fr);
      IntraRMFrame f = makeFrame(dets, kitti::readObjectLabels(ds.labelPath(fr)),
                                 ds.calibration(fr), config);
      if (!f.detections.empty()) frames.push_back(std::move(f));
    }
  }
  return frames;
}

std::vector<IntraRMFrame> loadIntraFrames(const std::string& data_dir, const io::SequenceDetections& detections,
                                          const relation::IntraRMTrainConfig& config) {
  kitti::TrackingDataset ds(data_dir);
  std::vector<IntraRMFrame> frames;
  for (const auto& [seq, per_frame] : detections) {
    if (!ds.hasLabels(seq)) throw std::runtime_error("sequence " + seq + ": no labels in " + ds.dir());
    const kitti::Calibration calib = kitti::readCalibration(ds.calibPath(seq));
    std::map<int, std::vector<kitti::Label>> gt;
    for (kitti::Label& l : kitti::readTrackingLabels(ds.labelPath(seq))) gt[l.frame].push_back(std::move(l));
    for (const auto& [frame, d] : per_frame) {
      if (d.empty()) continue;
      const auto it = gt.find(frame);
      // This package's boxes have no image box, so DontCare regions cannot be matched: none are ignored.
      const relation::FrameGroundTruth truth =
          groundTruth(it == gt.end() ? std::vector<kitti::Label>{} : it->second, calib, nullptr);
      IntraRMFrame f;
      f.detections = d;
      f.targets = relation::assignIntraRMTargets(d.boxes, truth, config, std::vector<bool>(d.size(), false));
      frames.push_back(std::move(f));
    }
  }
  return frames;
}

IntraTrainReport trainIntraRM(const std::vector<IntraRMFrame>& train, const std::vector<IntraRMFrame>& val,
                              const IntraTrainOptions& options) {
  IntraTrainReport report;
  for (const auto& f : train) report.train_boxes += f.detections.size();
  report.train_frames = train.size();
  report.val_frames = val.size();
  if (train.empty()) throw std::runtime_error("IntraRM training: no training frames with detections");
  trainRelationModule<relation::IntraRMLearner>("IntraRM", options, options.config.train.frames_per_batch, train, val,
                                                &report);
  // The saved model's scores made probabilities of a true positive, fitted on the training frames.
  relation::IntraRMOptions saved;
  saved.model_path = options.out_path;
  relation::IntraRM model(saved);
  const PerClass<std::size_t> used = relation::calibrateIntraRMScores(&model, train);
  model.save(options.out_path);
  const relation::IntraRMArch& a = model.arch();
  for (std::size_t c = 0; c < 3; ++c)
    RET3D_INFO("IntraRM score calibration " << className(kDetectedClasses[c]) << ": sigmoid(" << a.score_scale[c]
                                            << " * logit + " << a.score_bias[c] << "), fitted on " << used[c]
                                            << " boxes");
  return report;
}

}  // namespace train
}  // namespace ret3d
