#include "ret3d/tracking/track_history.h"

#include <algorithm>
#include <stdexcept>
#include <string>

#include "ret3d/core/transform.h"

namespace ret3d {

TrackHistory::TrackHistory(std::size_t capacity) : buffer_(capacity) {
  if (capacity == 0) throw std::invalid_argument("TrackHistory: capacity must be at least 1");
}

void TrackHistory::push(const Box& box_fixed, double stamp, const float* feature, std::size_t feature_dim) {
  if (!feature) feature_dim = 0;
  if (size_ == 0 && feature_dim != feature_dim_) {
    feature_dim_ = feature_dim;
    features_.assign(buffer_.size() * feature_dim_, 0.0f);
  } else if (feature_dim != feature_dim_) {
    throw std::invalid_argument("TrackHistory: feature of " + std::to_string(feature_dim) + " values pushed to a history of " +
                                std::to_string(feature_dim_));
  }
  std::size_t slot;
  if (size_ < buffer_.size()) {
    slot = (head_ + size_) % buffer_.size();
    ++size_;
  } else {
    slot = head_;
    head_ = (head_ + 1) % buffer_.size();
  }
  buffer_[slot] = HistoryEntry{box_fixed, stamp};
  if (feature_dim_) std::copy(feature, feature + feature_dim_, features_.begin() + slot * feature_dim_);
}

void TrackHistory::clear() {
  head_ = 0;
  size_ = 0;
}

std::vector<TimedBox> TrackHistory::inSensorFrame(double now, const Eigen::Isometry3d& sensor_to_fixed) const {
  const Eigen::Isometry3d fixed_to_sensor = sensor_to_fixed.inverse();
  std::vector<TimedBox> out;
  out.reserve(size_);
  for (std::size_t i = 0; i < size_; ++i) {
    const HistoryEntry& e = (*this)[i];
    out.push_back(TimedBox{transformBox(e.box, fixed_to_sensor), e.stamp - now});
  }
  return out;
}

}  // namespace ret3d
