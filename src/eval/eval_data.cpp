#include "ret3d/eval/eval_data.h"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <map>
#include <set>
#include <sstream>
#include <stdexcept>
#include <strings.h>

#include "ret3d/core/geometry.h"
#include "ret3d/core/log.h"
#include "ret3d/io/detections.h"
#include "parallel.h"

namespace ret3d {
namespace eval {

namespace fs = std::filesystem;

namespace {

bool sameType(const std::string& a, const char* b) { return strcasecmp(a.c_str(), b) == 0; }

}  // namespace

void fillGtBoxesFromLabels(EvalFrame& frame, const kitti::Calibration& calib) {
  frame.gt_boxes.clear();
  frame.gt_ignore.clear();
  frame.gt_box_label.clear();
  frame.gt_returns.clear();
  for (std::size_t i = 0; i < frame.gt_labels.size(); ++i) {
    const kitti::Label& l = frame.gt_labels[i];
    std::optional<ObjectClass> cls = classFromName(l.type);
    bool ignore = false;
    if (!cls && sameType(l.type, "Van")) {
      cls = ObjectClass::Car;
      ignore = true;
    } else if (!cls && sameType(l.type, "Person_sitting")) {
      cls = ObjectClass::Pedestrian;
      ignore = true;
    }
    if (!cls) continue;
    Box b = kitti::labelToBox(l, calib);
    b.label = *cls;
    b.score = 1.0f;
    frame.gt_boxes.push_back(b);
    frame.gt_ignore.push_back(ignore || (i < frame.gt_label_ignore.size() && frame.gt_label_ignore[i]));
    frame.gt_box_label.push_back(static_cast<int>(i));
  }
}

void fillPredBoxesFromLabels(EvalFrame& frame, const kitti::Calibration& calib) {
  frame.pred_boxes.clear();
  for (const auto& l : frame.pred_labels) {
    if (!classFromName(l.type)) continue;
    frame.pred_boxes.push_back(kitti::labelToBox(l, calib));
  }
}

std::vector<kitti::Label> boxesToCameraLabels(const std::vector<Box>& boxes, const kitti::Calibration& calib,
                                              const Eigen::Vector2d& image_size) {
  std::vector<kitti::Label> out;
  for (const Box& b : boxes) {
    kitti::Label l = kitti::boxToLabel(b, calib, image_size);
    if (b.label == ObjectClass::Unknown || l.z <= 0) continue;  // behind the camera
    const auto& bb = l.bbox;
    if (!(bb[2] > bb[0] && bb[3] > bb[1])) continue;  // projects outside the image
    l.truncated = 0;
    l.occluded = 0;
    out.push_back(std::move(l));
  }
  return out;
}

void fillLabelsFromBoxes(EvalFrame& frame, const kitti::Calibration& calib, const Eigen::Vector2d& image_size) {
  std::vector<Box> gt = frame.gt_boxes;
  for (std::size_t i = 0; i < gt.size() && i < frame.gt_ignore.size(); ++i) {
    if (frame.gt_ignore[i]) gt[i].label = ObjectClass::Unknown;  // neighbouring classes: re-added below
  }
  frame.gt_labels = boxesToCameraLabels(gt, calib, image_size);
  for (auto& l : frame.gt_labels) l.score.reset();
  for (std::size_t i = 0; i < frame.gt_ignore.size() && i < frame.gt_boxes.size(); ++i) {
    if (!frame.gt_ignore[i]) continue;
    Box b = frame.gt_boxes[i];
    auto ls = boxesToCameraLabels({b}, calib, image_size);
    if (ls.empty()) continue;
    ls[0].type = b.label == ObjectClass::Car ? "Van" : "Person_sitting";
    ls[0].score.reset();
    frame.gt_labels.push_back(ls[0]);
  }
  frame.pred_labels = boxesToCameraLabels(frame.pred_boxes, calib, image_size);
}

std::size_t countGroundTruthPoints(EvalData& data, int threads,
                                   const std::function<void(std::size_t, std::size_t)>& progress) {
  std::vector<std::size_t> todo;
  for (std::size_t i = 0; i < data.frames.size(); ++i) {
    if (!data.frames[i].velodyne_path.empty() && !data.frames[i].gt_boxes.empty()) todo.push_back(i);
  }
  detail::ProgressCounter counter(progress, todo.size());
  detail::parallelFor(todo.size(), threads, [&](std::size_t k) {
    EvalFrame& f = data.frames[todo[k]];
    const PointCloud cloud = kitti::readVelodyne(f.velodyne_path);
    const std::vector<std::uint32_t> counts = countPointsInBoxes(f.gt_boxes, cloud);
    for (std::size_t b = 0; b < counts.size(); ++b) f.gt_boxes[b].num_points = counts[b];
    counter.tick();
  });
  if (!todo.empty()) data.gt_has_point_counts = true;
  return todo.size();
}

namespace {

// The frame's returns in each ground-truth box grown by kLabelReturnMargin (far_cars.py's returns_in_label).
void countLabelReturns(EvalFrame& f) {
  std::vector<Box> grown = f.gt_boxes;
  for (Box& b : grown) {
    b.length += 2 * kLabelReturnMargin;
    b.width += 2 * kLabelReturnMargin;
    b.height += 2 * kLabelReturnMargin;
  }
  f.gt_returns = countPointsInBoxes(grown, kitti::readVelodyne(f.velodyne_path));
}

std::string frameName(const EvalFrame& f) {
  return (f.sequence.empty() ? "" : "sequence " + f.sequence + " ") + "frame " + std::to_string(f.frame);
}

}  // namespace

std::map<ObjectClass, MinPointsCounts> ignoreLabelsWithFewReturns(
    EvalData& data, int min_points, int threads, const std::function<void(std::size_t, std::size_t)>& progress) {
  if (min_points < 0) throw std::invalid_argument("--min-points: " + std::to_string(min_points) + " is negative");
  std::vector<std::size_t> todo;
  for (std::size_t i = 0; i < data.frames.size(); ++i) {
    const EvalFrame& f = data.frames[i];
    if (f.gt_boxes.empty()) continue;
    if (f.gt_box_label.size() != f.gt_boxes.size())
      throw std::invalid_argument("--min-points: the ground truth of " + frameName(f) +
                                  " is not from KITTI labels (a bag?); it needs a KITTI folder with the scans");
    if (f.velodyne_path.empty())
      throw std::runtime_error("--min-points: no scan for " + frameName(f) +
                               " (velodyne/ beside the labels): returns in the labels are counted from it");
    todo.push_back(i);
  }
  detail::ProgressCounter counter(progress, todo.size());
  detail::parallelFor(todo.size(), threads, [&](std::size_t k) {
    countLabelReturns(data.frames[todo[k]]);
    counter.tick();
  });
  std::map<ObjectClass, MinPointsCounts> counts;
  for (std::size_t i : todo) {
    EvalFrame& f = data.frames[i];
    f.gt_label_ignore.assign(f.gt_labels.size(), 0);
    for (std::size_t b = 0; b < f.gt_boxes.size(); ++b) {
      const bool few = f.gt_returns[b] < static_cast<std::uint32_t>(min_points);
      if (few) f.gt_label_ignore[static_cast<std::size_t>(f.gt_box_label[b])] = 1;
      if (!classFromName(f.gt_labels[static_cast<std::size_t>(f.gt_box_label[b])].type)) continue;  // Van, ...
      MinPointsCounts& c = counts[f.gt_boxes[b].label];
      ++(few ? c.ignored : c.kept);
      if (few) f.gt_ignore[b] = 1;
    }
  }
  return counts;
}

std::vector<LabelReturns> labelReturns(const EvalData& data) {
  std::vector<LabelReturns> out;
  for (const EvalFrame& f : data.frames) {
    for (std::size_t b = 0; b < f.gt_returns.size() && b < f.gt_boxes.size(); ++b) {
      const Box& box = f.gt_boxes[b];
      const kitti::Label& l = f.gt_labels[static_cast<std::size_t>(f.gt_box_label[b])];
      out.push_back({f.sequence, f.frame, f.gt_box_label[b], l.type, l.track_id, std::hypot(box.x, box.y),
                     f.gt_returns[b], f.gt_ignore[b] != 0});
    }
  }
  return out;
}

std::vector<std::string> parseSequenceList(const std::string& text) {
  std::vector<std::string> out;
  std::stringstream ss(text);
  std::string item;
  const auto number = [&](const std::string& s) {
    std::size_t pos = 0;
    int v = -1;
    try {
      v = std::stoi(s, &pos);
    } catch (const std::exception&) {
      pos = 0;
    }
    if (pos != s.size() || v < 0) throw std::invalid_argument("--sequences: not a sequence number: '" + s + "'");
    return v;
  };
  while (std::getline(ss, item, ',')) {
    if (item.empty()) continue;
    const auto dash = item.find('-');
    int a, b;
    if (dash == std::string::npos) {
      a = b = number(item);
    } else {
      a = number(item.substr(0, dash));
      b = number(item.substr(dash + 1));
    }
    if (b < a) throw std::invalid_argument("--sequences: empty range '" + item + "'");
    for (int s = a; s <= b; ++s) {
      char buf[16];
      std::snprintf(buf, sizeof buf, "%04d", s);
      out.push_back(buf);
    }
  }
  return out;
}

EvalData loadKittiTracking(const std::string& gt_root, const std::string& pred_dir,
                           const std::vector<std::string>& sequences_in) {
  kitti::TrackingDataset ds(gt_root);
  std::vector<std::string> sequences = sequences_in;
  if (sequences.empty()) {
    for (const auto& s : ds.sequences()) {
      if (ds.hasLabels(s)) sequences.push_back(s);
    }
  }
  if (sequences.empty()) throw std::runtime_error(gt_root + ": no labelled tracking sequences (label_02/SSSS.txt)");

  EvalData data;
  io::DetectionLayout layout = io::DetectionLayout::KittiTracking;
  const bool with_pred = !pred_dir.empty();
  if (with_pred) {
    layout = io::detectDetectionLayout(pred_dir);
    if (layout == io::DetectionLayout::KittiObject) {
      throw std::runtime_error(pred_dir + ": holds per-frame object results (FFFFFF.txt) but the ground truth is a "
                                          "tracking folder; give tracking results (SSSS.txt) or <Class>/SSSS.txt");
    }
    data.pred_description = pred_dir + " (" + io::layoutName(layout) + ")";
  }
  std::size_t n_gt = 0, n_pred = 0;
  for (const auto& seq : sequences) {
    if (!ds.hasLabels(seq)) throw std::runtime_error(ds.labelPath(seq) + ": missing (sequence " + seq + ")");
    const auto labels = kitti::readTrackingLabels(ds.labelPath(seq));
    const kitti::Calibration calib = kitti::readCalibration(ds.calibPath(seq));
    data.calibrations[seq] = calib;
    std::map<int, std::vector<kitti::Label>> gt_by_frame;
    int last = -1;
    for (const auto& l : labels) {
      gt_by_frame[l.frame].push_back(l);
      last = std::max(last, l.frame);
      if (l.track_id >= 0) data.gt_has_track_ids = true;
    }
    const std::vector<int> scans = ds.frames(seq);
    if (!scans.empty()) last = std::max(last, scans.back());
    const std::set<int> scan_set(scans.begin(), scans.end());
    std::map<int, std::vector<kitti::Label>> pred_by_frame;
    if (with_pred) pred_by_frame = io::readSequenceDetections(pred_dir, layout, seq);
    for (int f = 0; f <= last; ++f) {
      EvalFrame fr;
      fr.sequence = seq;
      fr.frame = f;
      if (auto it = gt_by_frame.find(f); it != gt_by_frame.end()) fr.gt_labels = it->second;
      if (auto it = pred_by_frame.find(f); it != pred_by_frame.end()) fr.pred_labels = it->second;
      for (const auto& l : fr.pred_labels) {
        if (l.track_id >= 0) data.pred_has_track_ids = true;
      }
      if (scan_set.count(f)) fr.velodyne_path = ds.velodynePath(seq, f);
      fillGtBoxesFromLabels(fr, calib);
      fillPredBoxesFromLabels(fr, calib);
      n_gt += fr.gt_labels.size();
      n_pred += fr.pred_labels.size();
      data.frames.push_back(std::move(fr));
    }
    if (!pred_by_frame.empty() && pred_by_frame.rbegin()->first > last) {
      RET3D_WARN(seq << ": predictions beyond the last frame " << last << " are not evaluated");
    }
  }
  std::ostringstream d;
  d << ds.dir() << " (KITTI tracking label_02, sequences " << sequences.front() << ".." << sequences.back() << ", "
    << sequences.size() << " sequences)";
  data.gt_description = d.str();
  RET3D_INFO("loaded " << data.frames.size() << " frames: " << n_gt << " ground-truth labels, " << n_pred
                       << " predictions");
  return data;
}

EvalData loadKittiObject(const std::string& gt_root, const std::string& pred_dir) {
  kitti::ObjectDataset ds(gt_root);
  EvalData data;
  std::vector<std::string> frames;
  if (!pred_dir.empty()) {
    const auto layout = io::detectDetectionLayout(pred_dir);
    if (layout != io::DetectionLayout::KittiObject) {
      throw std::runtime_error(pred_dir + ": expected per-frame object result files (FFFFFF.txt) for an object "
                                          "folder, found " + io::layoutName(layout));
    }
    const fs::path files = io::detectionFilesDir(pred_dir);
    for (const auto& e : fs::directory_iterator(files)) {
      if (e.path().extension() == ".txt") frames.push_back(e.path().stem().string());
    }
    std::sort(frames.begin(), frames.end());
    data.pred_description = pred_dir + " (" + std::string(io::layoutName(layout)) + ")";
  }
  if (frames.empty()) {
    for (const auto& f : ds.frames()) {
      if (fs::exists(ds.labelPath(f))) frames.push_back(f);
    }
  }
  for (const auto& name : frames) {
    EvalFrame fr;
    fr.frame = std::stoi(name);
    const std::string label_path = ds.labelPath(name);
    if (!fs::exists(label_path)) {
      throw std::runtime_error(label_path + ": no ground truth for the result file of frame " + name);
    }
    fr.gt_labels = kitti::readObjectLabels(label_path);
    if (!pred_dir.empty()) fr.pred_labels = io::readFrameDetections(pred_dir, name);
    const std::string calib_path = ds.calibPath(name);
    const kitti::Calibration calib =
        fs::exists(calib_path) ? kitti::readCalibration(calib_path) : kitti::defaultCalibration();
    if (fs::exists(ds.velodynePath(name))) fr.velodyne_path = ds.velodynePath(name);
    fillGtBoxesFromLabels(fr, calib);
    fillPredBoxesFromLabels(fr, calib);
    data.frames.push_back(std::move(fr));
  }
  if (data.frames.empty()) throw std::runtime_error(gt_root + ": no labelled frames (label_2/FFFFFF.txt)");
  data.gt_description = ds.dir() + " (KITTI object label_2, " + std::to_string(data.frames.size()) + " frames)";
  return data;
}

}  // namespace eval
}  // namespace ret3d
