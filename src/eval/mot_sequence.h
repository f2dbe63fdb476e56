// Internal to src/eval: one class of one sequence prepared for the tracking metrics (ids made contiguous, ignored
// ground truth and the predictions on it removed, similarities computed), and the HOTA accumulation over it.
#pragma once

#include <array>
#include <vector>

#include "ret3d/eval/mot_metrics.h"

namespace ret3d {
namespace eval {
namespace detail {

struct MotTimestep {
  std::vector<int> gt_ids, pred_ids;  // contiguous ids within the sequence
  std::vector<double> sim;            // gt x pred, row-major
  double at(std::size_t g, std::size_t p) const { return sim[g * pred_ids.size() + p]; }
};

struct MotSequence {
  std::vector<MotTimestep> steps;
  int num_gt_ids = 0, num_pred_ids = 0;
  int num_gt_dets = 0, num_pred_dets = 0;
};

// Sums over sequences from which the final HOTA fields follow (TrackEval's combine_sequences): counts, and the
// association scores and localisation weighted by each sequence's true positives.
struct HotaSums {
  std::array<double, kHotaAlphas> tp{}, fn{}, fp{}, assa_w{}, assre_w{}, asspr_w{}, loca_w{};
};

void accumulateHota(const MotSequence& seq, HotaSums& sums);
Hota finishHota(const HotaSums& sums);

}  // namespace detail
}  // namespace eval
}  // namespace ret3d
