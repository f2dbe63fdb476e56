// The tracked sequences InterRM refines from (Ret3D §3.3, the sequence S_i of eq. (6)), built from the tracker's
// output only: per track id, the track's past boxes in the fixed frame. One class for both places InterRM runs: the
// InterRM nodelet (which sees only the `tracked` messages) and the offline pipeline (TrackRefiner), so both hand
// InterRM the same sequences.
//
// A history is dropped when its id has not been seen for more than max_age frames: the tracker's max_age, after which
// it ends the track and never hands that id out again. A stamp before the previous frame's (a bag loop, a new
// sequence) clears every history.
#pragma once

#include <cstddef>
#include <cstdint>
#include <unordered_map>
#include <vector>

#include <Eigen/Geometry>

#include "ret3d/core/types.h"
#include "ret3d/relation/inter_rm.h"
#include "ret3d/tracking/track_history.h"

namespace ret3d {
namespace pipeline {

class TrackHistories {
 public:
  // length: boxes kept per track, the current one included (InterRM's max_history); max_age: the tracker's (frames).
  // Throws std::invalid_argument for length 0 or a negative max_age.
  TrackHistories(std::size_t length, int max_age);

  // InterRM's input for one frame and the rows of the tracked boxes it refines.
  struct Sequences {
    std::vector<relation::InterRMSequence> sequences;  // newest first, in the current sensor frame
    std::vector<std::size_t> rows;                      // index into `tracked` of each sequence's current box
    bool cleared = false;  // the stamp went backwards: every history (if any) was dropped first
  };

  // One frame of tracked boxes (sensor frame, at `stamp` s, the sensor's pose in the fixed frame): stores each box
  // with a track id in its track's history (fixed frame) and returns, for each of them in the order of `tracked`, its
  // sequence: the box exactly as tracked, then its past boxes moved into this frame's sensor frame, newest first, with
  // their time offsets (<= 0). Boxes without a track id (0) get none. Then ages out the histories of unseen ids.
  Sequences update(const std::vector<Box>& tracked, double stamp, const Eigen::Isometry3d& sensor_to_fixed);

  // Forgets every history (a new sequence).
  void clear();

  std::size_t size() const { return tracks_.size(); }  // ids with a history
  std::size_t length() const { return length_; }
  int maxAge() const { return max_age_; }
  // The stored history (fixed frame) of an id, nullptr when it has none.
  const TrackHistory* find(std::uint32_t track_id) const;

 private:
  struct Track {
    TrackHistory history;
    std::uint64_t last_frame = 0;
    explicit Track(std::size_t length) : history(length) {}
  };

  std::size_t length_;
  int max_age_;
  std::unordered_map<std::uint32_t, Track> tracks_;
  std::uint64_t frame_ = 0;
  bool has_stamp_ = false;
  double last_stamp_ = 0.0;
};

// Writes InterRM's refined boxes (one per sequence) back into the tracked boxes they came from.
// Throws std::invalid_argument when the counts differ.
void applyRefined(const TrackHistories::Sequences& sequences, const std::vector<Box>& refined,
                  std::vector<Box>& tracked);

}  // namespace pipeline
}  // namespace ret3d
