// KITTI object detection AP, computed exactly as the official devkit (evaluate_object_3d_offline.cpp with the 2017
// minimum-height fix): 2D (image boxes), AOS, BEV and 3D; 41 recall sample points; 11-point AP as the devkit
// prints it (mean of precision at sample indices 0, 4, ..., 40) and R40 (mean over indices 1..40).
// Everything happens in KITTI camera coordinates straight from the labels (x right, y down, z forward; location is
// the bottom centre; rotation_y about y), as the devkit does, so the numbers match it.
#pragma once

#include <array>
#include <cstddef>
#include <functional>
#include <vector>

#include "ret3d/core/types.h"
#include "ret3d/io/kitti.h"

namespace ret3d {
namespace eval {

enum class KittiMetric { Box2D = 0, Bev = 1, Box3D = 2 };
enum class KittiDifficulty { Easy = 0, Moderate = 1, Hard = 2 };
inline constexpr int kKittiNumMetrics = 3;
inline constexpr int kKittiNumDifficulties = 3;
inline constexpr int kKittiSamplePoints = 41;

const char* metricKey(KittiMetric m);          // "2d", "bev", "3d"
const char* difficultyKey(KittiDifficulty d);  // "easy", "moderate", "hard"

// The devkit's difficulty definitions (KITTI object benchmark).
inline constexpr double kKittiMinHeight[3] = {40, 25, 25};       // 2D box height, pixels
inline constexpr int kKittiMaxOcclusion[3] = {0, 1, 2};
inline constexpr double kKittiMaxTruncation[3] = {0.15, 0.3, 0.5};

// One image: ground-truth labels (all types, including DontCare, Van, Person_sitting) and detections (with score).
struct KittiFrame {
  std::vector<kitti::Label> gt;
  std::vector<kitti::Label> det;
  // Parallel to gt (empty: none): labels ignored as the devkit ignores a neighbouring class (e.g. too few returns,
  // EvalFrame::gt_label_ignore): no miss when unmatched, a detection on it neither a true nor a false positive.
  std::vector<char> gt_ignore;
};

struct KittiApOptions {
  std::vector<ObjectClass> classes{ObjectClass::Car, ObjectClass::Pedestrian, ObjectClass::Cyclist};
  // Minimum overlap per class, indexed by ObjectClass value - 1 (Car, Pedestrian, Cyclist); the same for 2D, BEV and
  // 3D. Default: the benchmark's 0.7 / 0.5 / 0.5; kKittiLooseOverlap is the common loose setting.
  std::array<double, 3> min_overlap{{0.7, 0.5, 0.5}};
  int threads = 2;
  // How precision is sampled at the 41 recall points. Devkit: its getThresholds, which adds one score threshold per
  // true positive and takes the k-th threshold as recall k/40. That holds only with 40 or more valid ground truths per
  // class and difficulty: with fewer, a detector matching every object still scores (TP - 1) / 40 at R40 (the
  // ground truth itself scores 12.5 for the 6 moderate cars of six labelled frames). Exact: every true positive's
  // score is a threshold, and the precision at recall k/40 is the best precision at an actual recall >= k/40 (the
  // same matching, TP/FP/FN and DontCare rules); on large sets the two agree closely. For small validation sets.
  bool exact_recall = false;
  // Called after each finished piece of work (from worker threads, serialised): done, total.
  std::function<void(std::size_t, std::size_t)> progress;
};
inline constexpr std::array<double, 3> kKittiStrictOverlap{{0.7, 0.5, 0.5}};
inline constexpr std::array<double, 3> kKittiLooseOverlap{{0.5, 0.25, 0.25}};

// Precision (or orientation similarity) at the 41 recall sample points, after the devkit's max-to-the-right filter
// (with exact_recall: at recall k / 40 exactly).
struct KittiCurve {
  std::vector<double> precision = std::vector<double>(kKittiSamplePoints, 0.0);
  std::vector<double> recall;      // actual recall at each evaluated score threshold (<= 41 entries)
  std::vector<double> thresholds;  // the score thresholds themselves
  int num_gt = 0;                  // valid ground truth (recall denominator)

  double ap11() const;  // percent
  double ap40() const;  // percent
};

struct KittiClassResult {
  ObjectClass cls = ObjectClass::Unknown;
  double min_overlap = 0;
  int num_det = 0;  // detections of this class
  // [metric][difficulty]
  std::array<std::array<KittiCurve, kKittiNumDifficulties>, kKittiNumMetrics> curves;
  // Orientation similarity per difficulty (2D matching); valid only when KittiResult::aos_valid.
  std::array<KittiCurve, kKittiNumDifficulties> aos;
};

// Boxes a user would call false: detections of an evaluated class whose BEV IoU with every label of any type
// (Van, Truck, Misc, Person_sitting and the other classes included; any difficulty) stays below 0.1 and that do not
// lie in a DontCare region (over half of the detection's 2D box, the devkit's DontCare rule). Boxes on walls, poles
// and vegetation, not boxes of the wrong size or class on a real object. Counted at every score, and from score 0.5.
struct KittiFalseBoxes {
  std::array<int, 3> per_class{{0, 0, 0}};        // indexed by ObjectClass value - 1
  std::array<int, 3> per_class_score50{{0, 0, 0}};
  int total() const { return per_class[0] + per_class[1] + per_class[2]; }
  int totalScore50() const { return per_class_score50[0] + per_class_score50[1] + per_class_score50[2]; }
};

struct KittiResult {
  std::vector<KittiClassResult> classes;
  bool aos_valid = true;  // false when some detection has alpha == -10 (the devkit then skips AOS)
  bool exact_recall = false;  // KittiApOptions::exact_recall of the run
  std::size_t num_frames = 0;
  KittiFalseBoxes false_boxes;
};

KittiResult evaluateKitti(const std::vector<KittiFrame>& frames, const KittiApOptions& options = {});

// ---- the devkit's building blocks, exposed for tests ----
// Overlap of a detection with a ground truth: criterion -1 IoU, 0 over the detection's area, 1 over the gt's.
double kittiImageOverlap(const kitti::Label& det, const kitti::Label& gt, int criterion = -1);
// BEV: rotated rectangles (x, z, l, w, rotation_y) on the ground plane.
double kittiBevOverlap(const kitti::Label& det, const kitti::Label& gt, int criterion = -1);
// 3D: BEV intersection times the overlap along camera y (a box spans [y - h, y]: y points down).
double kitti3dOverlap(const kitti::Label& det, const kitti::Label& gt, int criterion = -1);
// Scores of true positives -> the score thresholds that sample recall at 41 points (devkit getThresholds).
std::vector<double> kittiThresholds(std::vector<double> tp_scores, int num_gt);
// Precision interpolated at recall k / 40, k = 0..40: the best precision at an actual recall of at least k / 40
// (0 where the recall is never reached). `recall` and `precision` are per score threshold.
std::vector<double> kittiExactSamples(const std::vector<double>& recall, const std::vector<double>& precision);
double kittiAp11(const std::vector<double>& precision);  // percent
double kittiAp40(const std::vector<double>& precision);  // percent

}  // namespace eval
}  // namespace ret3d
