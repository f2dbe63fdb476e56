// A track's past boxes for InterRM (Ret3D §3.3, the sequence S_i of eq. (6)): a fixed-capacity ring buffer of boxes in
// the fixed frame with their stamps, moved into the current sensor frame when used.
#pragma once

#include <cstddef>
#include <vector>

#include <Eigen/Geometry>

#include "ret3d/core/types.h"

namespace ret3d {

struct HistoryEntry {
  Box box;             // in the fixed (odom) frame; velocity over ground in that frame
  double stamp = 0.0;  // s
};

// A history entry as InterRM consumes it: the box in the current sensor frame and its time offset from now.
struct TimedBox {
  Box box;            // in the sensor frame of the current scan
  double dt = 0.0;    // stamp - now (s): <= 0 for past entries, 0 for the current detection
};

class TrackHistory {
 public:
  explicit TrackHistory(std::size_t capacity);

  // Appends; when full, the oldest entry is overwritten. `feature` (feature_dim floats, e.g. the detector's feature
  // of the box) is kept beside the box when given. The first push after construction or clear() fixes featureDim();
  // a later push with another feature_dim throws std::invalid_argument.
  void push(const Box& box_fixed, double stamp, const float* feature = nullptr, std::size_t feature_dim = 0);
  void clear();

  std::size_t size() const { return size_; }
  std::size_t capacity() const { return buffer_.size(); }
  bool empty() const { return size_ == 0; }
  // i = 0 is the oldest entry kept, size() - 1 the newest.
  const HistoryEntry& operator[](std::size_t i) const { return buffer_[(head_ + i) % buffer_.size()]; }
  const HistoryEntry& newest() const { return (*this)[size_ - 1]; }
  // Feature of entry i (featureDim() floats), nullptr when the history has no features.
  std::size_t featureDim() const { return feature_dim_; }
  const float* feature(std::size_t i) const {
    return feature_dim_ ? features_.data() + ((head_ + i) % buffer_.size()) * feature_dim_ : nullptr;
  }

  // All entries, oldest first, moved into the sensor frame whose pose in the fixed frame is sensor_to_fixed, with
  // time offsets relative to `now` (Ret3D §3.3: "the location features from past time-stamps have been projected to
  // the current frame's coordinate system").
  std::vector<TimedBox> inSensorFrame(double now, const Eigen::Isometry3d& sensor_to_fixed) const;

 private:
  std::vector<HistoryEntry> buffer_;
  std::vector<float> features_;  // capacity() x feature_dim_, slot-aligned with buffer_
  std::size_t feature_dim_ = 0;
  std::size_t head_ = 0;  // index of the oldest entry
  std::size_t size_ = 0;
};

}  // namespace ret3d
