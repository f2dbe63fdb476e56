// Track-id stability against ground truth: of the ground-truth track-frames that an output object covers, the share
// whose output track id is the one that ground-truth track was covered by most often. A tracker that keeps one id
// per object scores 100 % whatever its detection recall; every id switch, and every frame a track spends under a
// second id, lowers it. It is the figure the bag-replay harness (test/rostest/replay_accuracy.cpp) asserts (>= 90 %) and a summary can print beside
// MOTA, which mixes detection errors in.
//
// Matching, per frame and class: ground truth and output boxes of the same class are paired one to one by the optimal
// (Hungarian) assignment on centre distance, as TrackEval's point-like matching (motSimilarity with
// MotSimilarity::CenterDistance: similarity 1 - d / max_center_distance), and a pair counts when its centres are
// closer than max_center_distance. Ground truth marked ignore (EvalFrame::gt_ignore) takes no part. Ids are per
// sequence (EvalFrame::sequence). An output box without a track id (0) can be matched but never counts as stable.
#pragma once

#include <cstddef>
#include <vector>

#include "ret3d/core/types.h"
#include "ret3d/eval/eval_data.h"

namespace ret3d {
namespace eval {

struct IdStabilityOptions {
  std::vector<ObjectClass> classes{ObjectClass::Car, ObjectClass::Pedestrian, ObjectClass::Cyclist};
  double max_center_distance = 2.0;  // metres between box centres (3D)
};

struct IdStabilityCounts {
  std::size_t gt_track_frames = 0;  // ground-truth boxes of the class (not ignored)
  std::size_t matched = 0;          // of those, covered by an output box
  std::size_t stable = 0;           // of the matched, carrying their track's most frequent output id
  std::size_t gt_tracks = 0;        // ground-truth tracks matched at least once
  std::size_t output_ids = 0;       // distinct (sequence, output id) pairs over all matches (0 excluded)

  // stable / matched in percent; 0 when nothing was matched.
  double stability() const { return matched == 0 ? 0.0 : 100.0 * static_cast<double>(stable) / matched; }
  // matched / gt_track_frames in percent: how much of the ground truth the figure speaks for.
  double coverage() const {
    return gt_track_frames == 0 ? 0.0 : 100.0 * static_cast<double>(matched) / gt_track_frames;
  }
};

struct IdStabilityClassResult {
  ObjectClass cls = ObjectClass::Unknown;
  IdStabilityCounts counts;
};

struct IdStabilityResult {
  std::vector<IdStabilityClassResult> classes;  // in the order of IdStabilityOptions::classes
  IdStabilityCounts all;                        // every class pooled (track-frames, not a mean of classes)
};

// Throws std::invalid_argument when a ground-truth box of an evaluated class (not ignored) has no track id, or when
// max_center_distance is not positive.
IdStabilityResult evaluateIdStability(const std::vector<EvalFrame>& frames, const IdStabilityOptions& options = {});

}  // namespace eval
}  // namespace ret3d
