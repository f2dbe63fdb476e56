#include "ret3d/tracking/greedy_tracker.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>

#include "ret3d/core/log.h"
#include "ret3d/core/transform.h"
#include "ret3d/core/hungarian.h"

namespace ret3d {

struct GreedyTracker::Candidate {
  std::size_t index = 0;  // into the detections of update()
  Box fixed;              // the detection in the fixed frame
  bool has_velocity = false;
};

namespace {

bool finiteBox(const Box& b) {
  return std::isfinite(b.x) && std::isfinite(b.y) && std::isfinite(b.z) && std::isfinite(b.length) &&
         std::isfinite(b.width) && std::isfinite(b.height) && std::isfinite(b.yaw) && std::isfinite(b.vx) &&
         std::isfinite(b.vy) && std::isfinite(b.score);
}

bool isTrackedClass(ObjectClass c) {
  return c == ObjectClass::Car || c == ObjectClass::Pedestrian || c == ObjectClass::Cyclist;
}

}  // namespace

GreedyTracker::GreedyTracker(const TrackerOptions& options) : options_(options) { validate(options_); }

void GreedyTracker::reset() { tracks_.clear(); }

std::vector<Box> GreedyTracker::update(const std::vector<Box>& detections, double stamp,
                                       const Eigen::Isometry3d& sensor_to_fixed) {
  std::vector<Box> out;
  step(detections, nullptr, 0, stamp, sensor_to_fixed, out);
  return out;
}

Detections GreedyTracker::update(const Detections& detections, double stamp,
                                 const Eigen::Isometry3d& sensor_to_fixed) {
  detections.validate();
  Detections out;
  const std::vector<std::size_t> rows =
      step(detections.boxes, detections.hasFeatures() ? detections.features.data() : nullptr, detections.feature_dim,
            stamp, sensor_to_fixed, out.boxes);
  out.feature_dim = detections.feature_dim;
  out.features.reserve(rows.size() * out.feature_dim);
  for (std::size_t r : rows)
    out.features.insert(out.features.end(), detections.feature(r), detections.feature(r) + out.feature_dim);
  return out;
}

std::vector<std::size_t> GreedyTracker::step(const std::vector<Box>& detections, const float* features,
                                             std::size_t feature_dim, double stamp,
                                             const Eigen::Isometry3d& sensor_to_fixed, std::vector<Box>& out) {
  if (!std::isfinite(stamp)) throw std::invalid_argument("GreedyTracker::update: stamp is not finite");
  if (!features) feature_dim = 0;
  if (!detections.empty()) restartOnNewFeatureSize(feature_dim);
  const double dt = advanceClock(stamp, sensor_to_fixed);
  CandidatesByClass by_class = prepareCandidates(detections, sensor_to_fixed);

  FrameOutput frame;
  frame.boxes.resize(detections.size());
  frame.emitted.assign(detections.size(), 0);
  std::vector<char> track_matched(tracks_.size(), 0);
  std::vector<Track> born;
  for (ObjectClass label : kDetectedClasses) {
    std::vector<Candidate>& dets = by_class[static_cast<int>(label)];
    std::stable_sort(dets.begin(), dets.end(),
                     [](const Candidate& a, const Candidate& b) { return a.fixed.score > b.fixed.score; });
    std::vector<int> det_to_track;
    associate(label, dets, dt, stamp, det_to_track);
    for (std::size_t k = 0; k < dets.size(); ++k) {
      const Candidate& c = dets[k];
      Track* track = nullptr;
      if (det_to_track[k] >= 0) {
        track = &tracks_[det_to_track[k]];
        track_matched[det_to_track[k]] = 1;
      } else {
        if (!mayBeBorn(label, c.fixed.score)) continue;
        born.push_back(birth(label));
        track = &born.back();
      }
      updateTrack(*track, c, stamp, features ? features + c.index * feature_dim : nullptr, feature_dim);
      if (track->confirmed && c.fixed.score >= options_.output_score.at(label))
        emit(*track, c, detections[c.index], sensor_to_fixed.linear(), frame);
    }
  }
  ageTracks(track_matched, dt);
  for (Track& b : born) tracks_.push_back(std::move(b));

  out.clear();
  std::vector<std::size_t> rows;
  for (std::size_t i = 0; i < detections.size(); ++i) {
    if (!frame.emitted[i]) continue;
    out.push_back(frame.boxes[i]);
    rows.push_back(i);
  }
  return rows;
}

// Start: histories hold one feature size, so a new producer (another detector, a stage switched off) starts afresh.
void GreedyTracker::restartOnNewFeatureSize(std::size_t feature_dim) {
  if (feature_dim == feature_dim_) return;
  if (!tracks_.empty()) {
    RET3D_WARN("tracker reset: detection features changed from " << feature_dim_ << " to " << feature_dim
                                                                  << " values; dropped " << tracks_.size()
                                                                  << " tracks");
    reset();
    ++num_resets_;
  }
  feature_dim_ = feature_dim;
}

// Start: the time since the previous frame; a jump backwards (bag loop) or a gap over max_time_gap drops all tracks.
double GreedyTracker::advanceClock(double stamp, const Eigen::Isometry3d& sensor_to_fixed) {
  double dt = 0.0;
  if (has_stamp_) {
    dt = stamp - last_stamp_;
    if (dt < 0.0 || dt > options_.max_time_gap) {
      RET3D_WARN("tracker reset: stamp " << std::fixed << stamp << " is "
                                         << (dt < 0.0 ? "before the previous one (" : "more than max_time_gap after (")
                                         << last_stamp_ << "), " << (dt < 0.0 ? "bag loop?" : "gap") << "; dropped "
                                         << tracks_.size() << " tracks");
      reset();
      ++num_resets_;
      dt = 0.0;
    }
  }
  has_stamp_ = true;
  last_stamp_ = stamp;
  last_sensor_to_fixed_ = sensor_to_fixed;
  return dt;
}

// Start: the valid detections of tracked classes above score_threshold, in the fixed frame, grouped by class.
GreedyTracker::CandidatesByClass GreedyTracker::prepareCandidates(const std::vector<Box>& detections,
                                                                  const Eigen::Isometry3d& sensor_to_fixed) {
  CandidatesByClass by_class;
  std::size_t skipped_invalid = 0;
  for (std::size_t i = 0; i < detections.size(); ++i) {
    const Box& d = detections[i];
    if (!finiteBox(d)) {
      ++skipped_invalid;
      continue;
    }
    if (!isTrackedClass(d.label)) {
      if (!warned_unknown_class_) {
        RET3D_WARN("tracker: detections of class " << className(d.label) << " are not tracked (said once)");
        warned_unknown_class_ = true;
      }
      continue;
    }
    if (d.score < options_.score_threshold) continue;
    Candidate c;
    c.index = i;
    c.fixed = transformBox(d, sensor_to_fixed);
    // Exactly zero velocity is how detectors without a velocity head (and KITTI files) say "unknown".
    c.has_velocity = options_.use_detection_velocity && (d.vx != 0.0 || d.vy != 0.0);
    by_class[static_cast<int>(d.label)].push_back(std::move(c));
  }
  if (skipped_invalid > 0) RET3D_WARN("tracker: skipped " << skipped_invalid << " detections with non-finite fields");
  return by_class;
}

// Birth and confirmation, the one place that decides them. An unmatched detection starts a tentative track when its
// score reaches birth_score; a tentative track is confirmed (its boxes output) once a matched score reaches
// confirm_score or it has been matched min_hits times (birth included). Tentative tracks end at their first miss
// (ageTracks).
bool GreedyTracker::mayBeBorn(ObjectClass label, double score) const { return score >= options_.birth_score.at(label); }

bool GreedyTracker::confirms(const Track& track, double score) const {
  return score >= options_.confirm_score.at(track.label) || track.hits >= options_.min_hits.at(track.label);
}

// Birth: a new tentative track with the next id.
GreedyTracker::Track GreedyTracker::birth(ObjectClass label) {
  Track track(static_cast<std::size_t>(options_.history_length));
  track.id = next_id_++;
  track.label = label;
  return track;
}

// Update: the track takes the detection's centre, its velocity (given, else estimated from the history), a hit
// while tentative, and the box (with the track's velocity and id) into its history.
void GreedyTracker::updateTrack(Track& track, const Candidate& c, double stamp, const float* feature,
                                std::size_t feature_dim) {
  Box fixed = c.fixed;
  const Eigen::Vector3d centre = fixed.center();
  if (c.has_velocity) {
    track.velocity = Eigen::Vector2d(fixed.vx, fixed.vy);
    track.velocity_known = true;
  } else {
    track.velocity_known = estimateVelocity(track.history, centre, stamp, track.velocity);
    if (!track.velocity_known) track.velocity.setZero();
    fixed.vx = track.velocity.x();
    fixed.vy = track.velocity.y();
  }
  track.position = centre;
  track.last_seen = stamp;
  track.misses = 0;
  if (!track.confirmed) {
    ++track.hits;
    track.confirmed = confirms(track, c.fixed.score);
  }
  fixed.track_id = track.id;
  track.history.push(fixed, stamp, feature, feature_dim);
}

// Output: the detection as given (sensor frame) with the track's id, and the track's velocity when the detection had
// none.
void GreedyTracker::emit(const Track& track, const Candidate& c, const Box& detection, const Eigen::Matrix3d& R,
                         FrameOutput& frame) const {
  Box out = detection;
  out.track_id = track.id;
  if (!c.has_velocity) {
    const Eigen::Vector3d v = R.transpose() * Eigen::Vector3d(track.velocity.x(), track.velocity.y(), 0.0);
    out.vx = v.x();
    out.vy = v.y();
  }
  frame.boxes[c.index] = out;
  frame.emitted[c.index] = 1;
}

// Age: unmatched tracks coast on their velocity (not output); those unmatched for more than max_age frames end, and
// tentative ones at their first miss.
void GreedyTracker::ageTracks(const std::vector<char>& track_matched, double dt) {
  std::size_t kept = 0;
  for (std::size_t t = 0; t < tracks_.size(); ++t) {
    Track& tr = tracks_[t];
    if (!track_matched[t]) {
      if (++tr.misses > options_.max_age || !tr.confirmed) continue;
      if (tr.velocity_known) tr.position.head<2>() += tr.velocity * dt;
    }
    if (kept != t) tracks_[kept] = std::move(tr);
    ++kept;
  }
  tracks_.erase(tracks_.begin() + static_cast<std::ptrdiff_t>(kept), tracks_.end());
}

// Predict: the BEV distance between a detection and a track brought to the same instant, or infinity outside the
// gate.
double GreedyTracker::predictedDistance(const Candidate& c, const Track& tr, double dt, double now) const {
  Eigen::Vector2d det_xy(c.fixed.x, c.fixed.y);
  Eigen::Vector2d trk_xy = tr.position.head<2>();
  double g = options_.gate.at(tr.label);
  if (c.has_velocity) {
    det_xy -= Eigen::Vector2d(c.fixed.vx, c.fixed.vy) * dt;  // CenterPoint: the detection moved back in time
  } else if (tr.velocity_known) {
    trk_xy += tr.velocity * dt;  // no detection velocity: the track moved forward instead
  } else {
    // Neither velocity known: the object may have moved up to max_speed since the track was last seen.
    g += options_.max_speed.at(tr.label) * (now - tr.last_seen);
  }
  const double d = (det_xy - trk_xy).norm();
  return d <= g ? d : std::numeric_limits<double>::infinity();
}

// Associate: one class's detections (descending score) to its tracks, greedily or by the optimal assignment.
void GreedyTracker::associate(ObjectClass label, const std::vector<Candidate>& dets, double dt, double now,
                              std::vector<int>& det_to_track) {
  det_to_track.assign(dets.size(), -1);
  std::vector<int> cls_tracks;
  for (std::size_t t = 0; t < tracks_.size(); ++t)
    if (tracks_[t].label == label) cls_tracks.push_back(static_cast<int>(t));
  if (dets.empty() || cls_tracks.empty()) return;

  const double kForbidden = std::numeric_limits<double>::infinity();
  Eigen::MatrixXd cost(dets.size(), cls_tracks.size());
  for (std::size_t k = 0; k < dets.size(); ++k)
    for (std::size_t j = 0; j < cls_tracks.size(); ++j) cost(k, j) = predictedDistance(dets[k], tracks_[cls_tracks[j]], dt, now);

  if (options_.assignment == AssignmentMethod::Greedy) {
    std::vector<char> taken(cls_tracks.size(), 0);
    for (std::size_t k = 0; k < dets.size(); ++k) {  // dets are in descending score
      int best = -1;
      for (std::size_t j = 0; j < cls_tracks.size(); ++j)
        if (!taken[j] && cost(k, j) < kForbidden && (best < 0 || cost(k, j) < cost(k, best))) best = static_cast<int>(j);
      if (best >= 0) {
        taken[best] = 1;
        det_to_track[k] = cls_tracks[best];
      }
    }
  } else {
    // Forbidden pairs get a cost above any sum of allowed ones, so the optimum first maximises the number of allowed
    // pairs and then minimises their total distance; forbidden pairs it is forced into are dropped.
    double allowed_sum = 0.0;
    for (Eigen::Index i = 0; i < cost.size(); ++i)
      if (cost.data()[i] < kForbidden) allowed_sum += cost.data()[i];
    const double big = 2.0 * allowed_sum + 1.0;
    const Eigen::MatrixXd finite = cost.unaryExpr([&](double v) { return v < kForbidden ? v : big; });
    const std::vector<int> assignment = solveAssignment(finite);
    for (std::size_t k = 0; k < dets.size(); ++k) {
      const int j = assignment[k];
      if (j >= 0 && cost(k, j) < kForbidden) det_to_track[k] = cls_tracks[j];
    }
  }
}

bool GreedyTracker::estimateVelocity(const TrackHistory& history, const Eigen::Vector3d& current, double stamp,
                                     Eigen::Vector2d& velocity) const {
  // Least-squares slope of x(t), y(t) over the last velocity_window centres (current included): less noisy than the
  // last difference, and it adapts within velocity_window frames when the object changes speed.
  const std::size_t window = static_cast<std::size_t>(options_.velocity_window);
  const std::size_t from_history = std::min(history.size(), window - 1);
  if (from_history == 0) return false;
  // Sums over (t, p) with t relative to `stamp`, for precision with epoch stamps.
  double n = 0.0, st = 0.0, stt = 0.0;
  Eigen::Vector2d sp = Eigen::Vector2d::Zero(), stp = Eigen::Vector2d::Zero();
  auto add = [&](double t, const Eigen::Vector2d& p) {
    n += 1.0;
    st += t;
    stt += t * t;
    sp += p;
    stp += t * p;
  };
  for (std::size_t i = history.size() - from_history; i < history.size(); ++i) {
    const HistoryEntry& e = history[i];
    add(e.stamp - stamp, Eigen::Vector2d(e.box.x, e.box.y));
  }
  add(0.0, current.head<2>());
  const double denom = n * stt - st * st;
  if (denom < 1e-9) return false;  // all at one instant
  velocity = (n * stp - st * sp) / denom;
  return true;
}

std::vector<TimedBox> GreedyTracker::history(std::uint32_t track_id) const {
  const TrackHistory* h = findHistory(track_id);
  if (!h) return {};
  return h->inSensorFrame(last_stamp_, last_sensor_to_fixed_);
}

const TrackHistory* GreedyTracker::findHistory(std::uint32_t track_id) const {
  for (const Track& t : tracks_)
    if (t.id == track_id) return &t.history;
  return nullptr;
}

}  // namespace ret3d
