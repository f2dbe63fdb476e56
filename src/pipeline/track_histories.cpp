#include "ret3d/pipeline/track_histories.h"

#include <stdexcept>
#include <string>

#include "ret3d/core/transform.h"

namespace ret3d {
namespace pipeline {

TrackHistories::TrackHistories(std::size_t length, int max_age) : length_(length), max_age_(max_age) {
  if (length == 0) throw std::invalid_argument("TrackHistories: length must be at least 1");
  if (max_age < 0) throw std::invalid_argument("TrackHistories: max_age " + std::to_string(max_age) + " is negative");
}

void TrackHistories::clear() {
  tracks_.clear();
  has_stamp_ = false;
}

const TrackHistory* TrackHistories::find(std::uint32_t track_id) const {
  const auto it = tracks_.find(track_id);
  return it == tracks_.end() ? nullptr : &it->second.history;
}

TrackHistories::Sequences TrackHistories::update(const std::vector<Box>& tracked, double stamp,
                                                 const Eigen::Isometry3d& sensor_to_fixed) {
  Sequences out;
  if (has_stamp_ && stamp < last_stamp_) {
    out.cleared = true;
    tracks_.clear();
  }
  has_stamp_ = true;
  last_stamp_ = stamp;
  ++frame_;

  for (std::size_t i = 0; i < tracked.size(); ++i) {
    const Box& b = tracked[i];
    if (b.track_id == 0) continue;
    auto it = tracks_.find(b.track_id);
    if (it == tracks_.end()) it = tracks_.emplace(b.track_id, Track(length_)).first;
    it->second.last_frame = frame_;
    TrackHistory& history = it->second.history;
    if (!history.empty() && history.newest().stamp >= stamp) history.clear();  // one entry per stamp
    history.push(transformBox(b, sensor_to_fixed), stamp);
    const std::vector<TimedBox> past = history.inSensorFrame(stamp, sensor_to_fixed);  // oldest first
    relation::InterRMSequence seq;
    seq.boxes.reserve(past.size());
    seq.dt.reserve(past.size());
    seq.boxes.push_back(b);  // the current box exactly as tracked, not through the round trip to the fixed frame
    seq.dt.push_back(0.0);
    for (std::size_t k = past.size() - 1; k-- > 0;) {
      seq.boxes.push_back(past[k].box);
      seq.dt.push_back(past[k].dt);
    }
    out.sequences.push_back(std::move(seq));
    out.rows.push_back(i);
  }

  for (auto it = tracks_.begin(); it != tracks_.end();) {
    if (frame_ - it->second.last_frame > static_cast<std::uint64_t>(max_age_)) {
      it = tracks_.erase(it);
    } else {
      ++it;
    }
  }
  return out;
}

void applyRefined(const TrackHistories::Sequences& sequences, const std::vector<Box>& refined,
                  std::vector<Box>& tracked) {
  if (refined.size() != sequences.rows.size())
    throw std::invalid_argument("applyRefined: " + std::to_string(refined.size()) + " refined boxes for " +
                                std::to_string(sequences.rows.size()) + " sequences");
  for (std::size_t s = 0; s < refined.size(); ++s) tracked.at(sequences.rows[s]) = refined[s];
}

}  // namespace pipeline
}  // namespace ret3d
