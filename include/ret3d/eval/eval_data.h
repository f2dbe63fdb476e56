// Ground truth and predictions gathered into frames for the metrics: KITTI camera-frame labels for the KITTI AP
// (front camera view only) and LiDAR-frame boxes for Waymo AP/APH and the tracking metrics (360 degrees).
// Sources: a KITTI object folder (label_2 + calib), a KITTI tracking folder (label_02 + calib), result files in the
// layouts of io/detections.h, or boxes from a bag (converted to labels with a calibration, see fillLabelsFromBoxes).
#pragma once

#include <cstddef>
#include <cstdint>
#include <functional>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "ret3d/core/types.h"
#include "ret3d/io/kitti.h"

namespace ret3d {
namespace eval {

struct EvalFrame {
  std::string sequence;  // tracking sequence ("0001"), "" for object folders and bags
  int frame = 0;         // frame index within the sequence (or the object frame number, or the bag message index)
  double stamp = 0;      // seconds (bags); 0 otherwise

  // KITTI metrics: camera-frame labels. Ground truth keeps every type (DontCare, Van, ...), the devkit's input.
  std::vector<kitti::Label> gt_labels;
  std::vector<kitti::Label> pred_labels;

  // Waymo and tracking metrics: LiDAR-frame boxes of the three classes (label set), with track ids when known.
  std::vector<Box> gt_boxes;
  // Parallel to gt_boxes: true for a neighbouring class counted as its evaluated class's "ignore" region
  // (Van for Car, Person_sitting for Pedestrian): a prediction on it is neither a true nor a false positive.
  std::vector<char> gt_ignore;
  std::vector<Box> pred_boxes;
  // Parallel to gt_boxes: the index in gt_labels each box was made from (empty for ground truth not from labels).
  std::vector<int> gt_box_label;
  // Parallel to gt_boxes once counted (ignoreLabelsWithFewReturns): the scan's returns inside each box grown by
  // kLabelReturnMargin on every side.
  std::vector<std::uint32_t> gt_returns;
  // Parallel to gt_labels (empty: none): labels every metric ignores (too few returns), for the KITTI metrics.
  std::vector<char> gt_label_ignore;

  std::string velodyne_path;  // the scan, when available (Waymo difficulty from point counts)
};

struct EvalData {
  std::vector<EvalFrame> frames;
  std::string gt_description;    // what was read, for the report
  std::string pred_description;
  bool gt_has_track_ids = false;
  bool pred_has_track_ids = false;
  bool gt_has_point_counts = false;  // some ground-truth box has num_points > 0
  std::map<std::string, kitti::Calibration> calibrations;  // per sequence ("" for a single one), when read
};

// ---- label <-> box conversions used by the loaders ----
// Ground-truth labels of one frame -> gt_boxes/gt_ignore (Car, Pedestrian, Cyclist; Van and Person_sitting as
// ignore regions; other types dropped).
void fillGtBoxesFromLabels(EvalFrame& frame, const kitti::Calibration& calib);
// Prediction labels -> pred_boxes (the three classes only).
void fillPredBoxesFromLabels(EvalFrame& frame, const kitti::Calibration& calib);
// LiDAR boxes -> camera labels for the KITTI metrics: each box through kitti::boxToLabel, kept only when its centre
// is in front of the camera and its projected 2D box (clipped to the image) overlaps the image. Ground truth gets
// truncated/occluded 0 (a bag carries neither), so the difficulty then depends on the 2D box height alone.
// The conversion itself: boxes in front of the camera whose projection overlaps the image, as camera labels.
std::vector<kitti::Label> boxesToCameraLabels(const std::vector<Box>& boxes, const kitti::Calibration& calib,
                                              const Eigen::Vector2d& image_size = Eigen::Vector2d(1242, 375));
void fillLabelsFromBoxes(EvalFrame& frame, const kitti::Calibration& calib,
                         const Eigen::Vector2d& image_size = Eigen::Vector2d(1242, 375));

// ---- loaders ----
// Sequences of a KITTI tracking folder: ground truth from label_02 (frames 0 .. the last labelled or scanned frame),
// predictions from `pred_dir` (tracking result files or per-class comma-separated files). Empty `sequences` means
// every sequence with labels.
EvalData loadKittiTracking(const std::string& gt_root, const std::string& pred_dir,
                           const std::vector<std::string>& sequences);
// A KITTI object folder (label_2, calib) with per-frame result files. As the devkit's offline variant, the frames
// evaluated are those with a result file; when there are none at all, every labelled frame (with no predictions).
EvalData loadKittiObject(const std::string& gt_root, const std::string& pred_dir);

// Counts the scan's points inside every ground-truth box (Box::num_points) for frames with a velodyne_path, on
// `threads` threads; sets gt_has_point_counts when some frame was counted. Returns the number of frames counted.
std::size_t countGroundTruthPoints(EvalData& data, int threads = 2,
                                   const std::function<void(std::size_t, std::size_t)>& progress = nullptr);

// Returns of a label are the scan's points inside its box grown by this much (m) on every side (a box drawn tight to
// the object's surface leaves its own returns on the boundary).
inline constexpr double kLabelReturnMargin = 0.1;

// Labels per class holding enough returns, and those ignored for holding fewer than the minimum.
struct MinPointsCounts {
  std::size_t kept = 0, ignored = 0;
};

// The Waymo Open Dataset's rule for objects the sensor barely sees: counts the returns of every ground-truth box
// from its frame's scan (gt_returns) and marks the boxes with fewer than `min_points` as ignored by every metric
// (gt_ignore, and gt_label_ignore for the KITTI metrics): an unmatched one is not a miss, a prediction matched to it
// neither a true nor a false positive. Throws naming the frame when ground truth comes without its scan
// (velodyne_path) or not from labels (a bag). Returns the counts per class of Car, Pedestrian, Cyclist (Van and
// Person_sitting, ignored anyway, are not counted in them).
std::map<ObjectClass, MinPointsCounts> ignoreLabelsWithFewReturns(
    EvalData& data, int min_points, int threads = 2,
    const std::function<void(std::size_t, std::size_t)>& progress = nullptr);

// One counted ground-truth label: where it is, what it is and the returns it holds.
struct LabelReturns {
  std::string sequence;
  int frame = 0;
  int label = 0;  // index in the frame's label file (gt_labels)
  std::string type;
  int track_id = -1;
  double range = 0;  // m, horizontal from the sensor
  std::uint32_t returns = 0;
  bool ignored = false;  // by every metric (too few returns, or a neighbouring class)
};
// Every label counted by ignoreLabelsWithFewReturns, frame by frame.
std::vector<LabelReturns> labelReturns(const EvalData& data);

// Parses "1,3-5,0007" into {"0001","0003","0004","0005","0007"} (four-digit sequence names).
std::vector<std::string> parseSequenceList(const std::string& text);

}  // namespace eval
}  // namespace ret3d
