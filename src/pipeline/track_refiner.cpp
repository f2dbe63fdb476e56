#include "ret3d/pipeline/track_refiner.h"

#include <algorithm>
#include <chrono>

namespace ret3d {
namespace pipeline {

TrackRefiner::TrackRefiner(const TrackerOptions& tracker, const relation::InterRM* inter)
    : tracker_(tracker), inter_(inter) {
  if (inter_) {
    histories_ = std::make_unique<TrackHistories>(static_cast<std::size_t>(std::max(1, inter_->arch().max_history)),
                                                  tracker.max_age);
  }
}

void TrackRefiner::reset() {
  tracker_.reset();
  if (histories_) histories_->clear();
}

std::vector<Box> TrackRefiner::update(const std::vector<Box>& detections, double stamp,
                                      const Eigen::Isometry3d& sensor_to_fixed) {
  const auto t0 = std::chrono::steady_clock::now();
  std::vector<Box> tracked = tracker_.update(detections, stamp, sensor_to_fixed);
  const auto t1 = std::chrono::steady_clock::now();
  if (histories_) {
    const TrackHistories::Sequences s = histories_->update(tracked, stamp, sensor_to_fixed);
    if (!s.sequences.empty()) applyRefined(s, inter_->refine(s.sequences), tracked);
  }
  const auto t2 = std::chrono::steady_clock::now();
  tracker_s_ += std::chrono::duration<double>(t1 - t0).count();
  inter_s_ += std::chrono::duration<double>(t2 - t1).count();
  ++frames_;
  return tracked;
}

}  // namespace pipeline
}  // namespace ret3d
