// Waymo-style 3D detection AP and APH over 360 degrees, on LiDAR-frame boxes.
//
// - Matching, as the official Waymo metrics: per frame and class, at every score cutoff, the predictions at or above
//   it are assigned to the ground truth by Hungarian assignment maximising the total 3D IoU of the pairs whose IoU
//   reaches the class threshold (0.7 Car, 0.5 Pedestrian, 0.5 Cyclist). The cutoffs are the prediction scores
//   themselves (a frame's matching changes only at its own scores), so a higher-scored prediction may give its
//   ground truth up to a lower-scored one when that matches more pairs in total; greedy score-ordered matching
//   (COCO/KITTI) never does. Ignored ground truth (a neighbouring class such as Van for Car, or a box of a harder
//   level or another range bin) is not assigned; a prediction left unmatched that reaches the threshold on an ignored
//   box is dropped: neither true nor false positive. (The official tool also assigns boxes of a harder level and
//   drops what matches them; here valid ground truth comes first, as in KITTI's DontCare handling.)
// - Heading accuracy of a true positive: 1 - |wrap(yaw_pred - yaw_gt)| / pi (1 when aligned, 0 when reversed).
// - Levels from the points inside each ground-truth box: 0 points -> dropped (a prediction on it is a false
//   positive, as the box is not in the ground truth at all); 1..5 -> LEVEL_2; more -> LEVEL_1. LEVEL_1 evaluates
//   LEVEL_1 boxes (LEVEL_2 ones are ignored); LEVEL_2 evaluates both. Without point counts every box is LEVEL_1.
// - AP: the precision-recall curve over all score cutoffs, made monotone (precision at recall r = the maximum
//   precision at any recall >= r), integrated exactly over recall (area under the step curve). APH uses the same
//   rule on heading-weighted precision and recall (sum of heading accuracies over TP+FP and over the ground truth).
//   The official tool evaluates a fixed set of score cutoffs (configured, or quantiles of the scores); here every
//   distinct score is one.
#pragma once

#include <array>
#include <cstddef>
#include <functional>
#include <string>
#include <vector>

#include "ret3d/core/types.h"
#include "ret3d/eval/eval_data.h"

namespace ret3d {
namespace eval {

enum class WaymoLevel { L1 = 0, L2 = 1 };
inline constexpr int kWaymoNumLevels = 2;
const char* levelKey(WaymoLevel level);  // "L1", "L2"

struct RangeBin {
  double min = 0, max = 0;  // metres, horizontal distance from the sensor; [min, max)
  std::string name;         // "0-30", "30-50", "50+"
};

struct WaymoOptions {
  std::vector<ObjectClass> classes{ObjectClass::Car, ObjectClass::Pedestrian, ObjectClass::Cyclist};
  std::array<double, 3> iou_threshold{{0.7, 0.5, 0.5}};  // Car, Pedestrian, Cyclist (3D IoU)
  // When false (no counts and no scans), every ground-truth box is LEVEL_1 and none is dropped.
  bool use_point_counts = true;
  int level2_max_points = 5;
  std::vector<RangeBin> ranges{{0, 30, "0-30"}, {30, 50, "30-50"}, {50, 1e9, "50+"}};
  int threads = 2;
  std::function<void(std::size_t, std::size_t)> progress;
};

struct WaymoCurve {
  std::vector<double> recall, precision;       // one point per distinct score, descending score
  std::vector<double> recall_h, precision_h;   // heading-weighted
  double ap = 0, aph = 0;                      // percent
  int num_gt = 0, num_tp = 0, num_fp = 0;
};

struct WaymoClassResult {
  ObjectClass cls = ObjectClass::Unknown;
  double iou_threshold = 0;
  std::array<WaymoCurve, kWaymoNumLevels> levels;
  std::vector<std::array<WaymoCurve, kWaymoNumLevels>> ranges;  // per WaymoOptions::ranges
};

struct WaymoResult {
  std::vector<WaymoClassResult> classes;
  std::array<double, kWaymoNumLevels> mean_ap{{0, 0}}, mean_aph{{0, 0}};  // over classes with ground truth
  bool used_point_counts = false;
  std::size_t dropped_empty_gt = 0;  // ground-truth boxes without points
};

// Uses EvalFrame::gt_boxes (num_points for the levels), gt_ignore and pred_boxes.
WaymoResult evaluateWaymo(const std::vector<EvalFrame>& frames, const WaymoOptions& options = {});

double headingAccuracy(double yaw_pred, double yaw_gt);
// Area under the monotone (max-to-the-right) precision-recall step curve; recall ascending. Percent.
double interpolatedAp(const std::vector<double>& recall, const std::vector<double>& precision);

}  // namespace eval
}  // namespace ret3d
