#include "ret3d/tracking/track_history.h"

#include <stdexcept>

#include "ret3d/core/transform.h"

namespace ret3d {

TrackHistory::TrackHistory(std::size_t capacity) : buffer_(capacity) {
  if (capacity == 0) throw std::invalid_argument("TrackHistory: capacity must be at least 1");
}

void TrackHistory::push(const Box& box_fixed, double stamp) {
  if (size_ < buffer_.size()) {
    buffer_[(head_ + size_) % buffer_.size()] = HistoryEntry{box_fixed, stamp};
    ++size_;
  } else {
    buffer_[head_] = HistoryEntry{box_fixed, stamp};
    head_ = (head_ + 1) % buffer_.size();
  }
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
