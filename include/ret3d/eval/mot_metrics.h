// Multi-object tracking metrics per class, following TrackEval (the reference implementation of HOTA, whose CLEAR
// agrees with py-motmetrics): CLEAR MOT (Bernardin & Stiefelhagen 2008) and HOTA (Luiten et al. 2021).
//
// Similarity between a ground-truth box and a prediction: 3D IoU, BEV IoU, or centre distance turned into a
// similarity max(0, 1 - d / zero_distance) (TrackEval's convention for point-like matching).
// - CLEAR: per frame, pairs with similarity >= threshold are matched by Hungarian assignment, with a bonus that first
//   keeps the previous frame's matches; MOTA = 1 - (FN + FP + IDSW) / GT, MOTP = mean similarity of matches, IDSW =
//   matches whose prediction id differs from the one last matched to that ground-truth id, FRAG = per ground-truth
//   track the number of times it becomes tracked again after being untracked, MT / ML = ground-truth tracks matched
//   in > 80 % / < 20 % of their frames.
// - HOTA at each alpha in 0.05, 0.10, ..., 0.95: matching maximises global alignment x similarity; DetA = TP /
//   (TP + FN + FP), AssA = mean over TPs of the Jaccard index of their id pair, HOTA = sqrt(DetA * AssA); the
//   reported values are means over alpha (HOTA paper eq. 9-11).
// Ground truth marked ignore (EvalFrame::gt_ignore: Van for Car, Person_sitting for Pedestrian) is removed together
// with the predictions matched to it, as TrackEval does for KITTI's distractor classes.
// One deliberate difference from TrackEval: a frame without any prediction (or without any ground truth) ends the
// previous-frame matches like every other frame does; TrackEval skips such frames, so a track lost only in frames
// where the tracker output nothing at all would not count as fragmented there.
// Frames are grouped into sequences by EvalFrame::sequence (in order); ids are per sequence; Box::track_id 0 means
// "no id" and such boxes are rejected.
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

enum class MotSimilarity { Iou3d, IouBev, CenterDistance };
const char* similarityName(MotSimilarity s);  // "iou3d", "bev", "center"

struct MotOptions {
  std::vector<ObjectClass> classes{ObjectClass::Car, ObjectClass::Pedestrian, ObjectClass::Cyclist};
  MotSimilarity similarity = MotSimilarity::Iou3d;
  double threshold = 0.5;      // CLEAR: minimum similarity of a match (and of the ignore-region matching)
  double zero_distance = 2.0;  // CenterDistance: metres at which the similarity reaches 0
  // > 0: ground truth (ignored boxes too) and predictions whose centre lies further than this from the sensor (BEV,
  // LiDAR frame) are left out, as nuScenes' class ranges do, so that a detector is scored over the area it covers.
  double max_range = 0;
  int threads = 2;
};

inline constexpr int kHotaAlphas = 19;  // 0.05 .. 0.95

struct ClearMot {
  double mota = 0, motp = 0;  // percent
  int tp = 0, fp = 0, fn = 0, idsw = 0, frag = 0;
  int mt = 0, pt = 0, ml = 0, num_gt_tracks = 0, num_gt = 0;
};

struct Hota {
  double hota = 0, deta = 0, assa = 0, detre = 0, detpr = 0, assre = 0, asspr = 0, loca = 0;  // percent, mean over alpha
  std::array<double, kHotaAlphas> hota_alpha{}, deta_alpha{}, assa_alpha{};                 // percent
};

struct MotClassResult {
  ObjectClass cls = ObjectClass::Unknown;
  ClearMot clear;
  Hota hota;
  int num_pred_tracks = 0;
  int num_pred = 0;
};

struct MotResult {
  std::vector<MotClassResult> classes;
  std::size_t num_sequences = 0;
  std::size_t removed_on_ignore = 0;  // predictions dropped because they matched ignored ground truth
};

// Throws std::invalid_argument when a ground-truth or predicted box of an evaluated class has no track id.
MotResult evaluateMot(const std::vector<EvalFrame>& frames, const MotOptions& options = {});

double motSimilarity(const Box& gt, const Box& pred, const MotOptions& options);

}  // namespace eval
}  // namespace ret3d
