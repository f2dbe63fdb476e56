// The tracker followed by InterRM (Ret3D §3.3), one frame at a time: what runs online after the detector (and
// IntraRM) in the tracker and InterRM nodelets, here in one object for the offline pipeline, the benchmarks and the
// training code. InterRM's sequences come from TrackHistories, as in the InterRM nodelet.
#pragma once

#include <cstddef>
#include <memory>
#include <vector>

#include <Eigen/Geometry>

#include "ret3d/core/types.h"
#include "ret3d/pipeline/track_histories.h"
#include "ret3d/relation/inter_rm.h"
#include "ret3d/tracking/greedy_tracker.h"

namespace ret3d {
namespace pipeline {

class TrackRefiner {
 public:
  // `inter` may be null: tracking only. The refiner does not own it. With it, each track's history holds the model's
  // max_history boxes and ages out after the tracker's max_age.
  TrackRefiner(const TrackerOptions& tracker, const relation::InterRM* inter);
  // Tracks the frame's detections (sensor frame, at `stamp`, sensor pose in the fixed frame) and refines every tracked
  // box from its history. Returns the tracked boxes with track ids (sensor frame).
  std::vector<Box> update(const std::vector<Box>& detections, double stamp, const Eigen::Isometry3d& sensor_to_fixed);
  // A new sequence: forget the tracks and their histories (ids keep counting).
  void reset();
  const GreedyTracker& tracker() const { return tracker_; }
  // Boxes InterRM sees per track (the current one included); 0 without InterRM.
  std::size_t historyLength() const { return histories_ ? histories_->length() : 0; }

  double trackerSeconds() const { return tracker_s_; }
  double interSeconds() const { return inter_s_; }  // histories and InterRM
  std::size_t frames() const { return frames_; }

 private:
  GreedyTracker tracker_;
  const relation::InterRM* inter_;
  std::unique_ptr<TrackHistories> histories_;
  double tracker_s_ = 0, inter_s_ = 0;
  std::size_t frames_ = 0;
};

}  // namespace pipeline
}  // namespace ret3d
