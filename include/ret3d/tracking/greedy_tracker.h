// CenterPoint's greedy tracker (Yin, Zhou, Kraehenbuehl, CVPR 2021, §3 "Tracking"), the tracker Ret3D builds its
// object sequences with (Ret3D §3.3), run in a fixed frame so that ego motion does not move static objects.
//
// Per frame and per class: each detection's centre is moved back by its velocity times the time since the last frame
// and matched to the tracks' centres by BEV distance within a class gate, greedily in descending score (or optimally,
// Hungarian). Matched tracks take the detection; unmatched detections scoring at least birth_score start tracks with
// fresh ids; unmatched tracks coast on their velocity for up to max_age frames without being output. A track's boxes
// are output once it is confirmed (a detection scoring confirm_score, or min_hits consecutive matches from its birth),
// in the frames whose detection scores output_score; a tentative track ends at its first miss.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <vector>

#include <Eigen/Geometry>

#include "ret3d/core/detections.h"
#include "ret3d/core/types.h"
#include "ret3d/tracking/track_history.h"
#include "ret3d/tracking/tracker_options.h"

namespace ret3d {

class GreedyTracker {
 public:
  // Throws std::invalid_argument for invalid options (see validate()).
  explicit GreedyTracker(const TrackerOptions& options);

  // One frame: detections in the sensor frame at `stamp` (s), with the sensor's pose in the fixed frame. Returns the
  // tracked boxes of this frame in the sensor frame, in the detections' order: each a detection as given (all its
  // fields kept) with track_id > 0 set; when the detection carried no velocity (or use_detection_velocity is off),
  // (vx, vy) are the track's estimated velocity (zero until two observations). Detections below score_threshold,
  // of the Unknown class, or with non-finite fields are skipped; unmatched ones below birth_score are not output, nor
  // are the boxes of tentative (not yet confirmed) tracks.
  // A stamp before the previous one (a bag loop) or more than max_time_gap after it resets the tracker first, with
  // one log line; track ids keep counting, so they are never reused within the tracker's life.
  std::vector<Box> update(const std::vector<Box>& detections, double stamp, const Eigen::Isometry3d& sensor_to_fixed);
  // The same for a stage's Detections: each output box keeps its feature row, and the features are kept in the
  // tracks' histories beside the boxes (TrackHistory::feature). A change of feature_dim resets the tracker (logged).
  Detections update(const Detections& detections, double stamp, const Eigen::Isometry3d& sensor_to_fixed);

  // Forgets all tracks (ids keep counting).
  void reset();

  // The history of a live track (oldest first, the last entry being this frame's detection when it was matched),
  // moved into the sensor frame of the last update with time offsets relative to its stamp. Empty for an unknown id.
  std::vector<TimedBox> history(std::uint32_t track_id) const;
  // The stored history (fixed frame) of a live track, nullptr for an unknown id.
  const TrackHistory* findHistory(std::uint32_t track_id) const;

  // Live tracks, coasting ones included.
  std::size_t numTracks() const { return tracks_.size(); }
  // Resets caused by time jumps or gaps since construction.
  std::size_t numResets() const { return num_resets_; }
  // The largest id handed out so far (0 before the first track).
  std::uint32_t lastId() const { return next_id_ - 1; }
  const TrackerOptions& options() const { return options_; }

 private:
  struct Track {
    std::uint32_t id = 0;
    ObjectClass label = ObjectClass::Unknown;
    Eigen::Vector3d position = Eigen::Vector3d::Zero();  // fixed frame: last matched centre, advanced while coasting
    Eigen::Vector2d velocity = Eigen::Vector2d::Zero();  // fixed frame, m/s
    bool velocity_known = false;
    double last_seen = 0.0;  // stamp of the last match
    int misses = 0;          // consecutive frames without a match
    int hits = 0;            // frames matched (birth included) while tentative
    bool confirmed = false;  // its boxes are output (TrackerOptions::confirm_score, min_hits)
    TrackHistory history;
    explicit Track(std::size_t capacity) : history(capacity) {}
  };
  struct Candidate;  // a detection prepared for matching (fixed frame)
  using CandidatesByClass = std::array<std::vector<Candidate>, 4>;  // indexed by ObjectClass
  struct FrameOutput {  // the output box of each detection index, and whether it is output
    std::vector<Box> boxes;
    std::vector<char> emitted;
  };

  // Both update()s: features is boxes.size() x feature_dim or null; returns the detection index of each output box.
  // One frame runs the phases below in order: start, then per class predict + associate, update or birth, output;
  // then age.
  std::vector<std::size_t> step(const std::vector<Box>& boxes, const float* features, std::size_t feature_dim,
                                double stamp, const Eigen::Isometry3d& sensor_to_fixed, std::vector<Box>& out);

  // Start: drops all tracks when the detections' feature size changes.
  void restartOnNewFeatureSize(std::size_t feature_dim);
  // Start: seconds since the previous frame (0 after a reset for a backwards stamp or a gap over max_time_gap).
  double advanceClock(double stamp, const Eigen::Isometry3d& sensor_to_fixed);
  // Start: the trackable detections in the fixed frame, per class.
  CandidatesByClass prepareCandidates(const std::vector<Box>& detections, const Eigen::Isometry3d& sensor_to_fixed);
  // Predict: detection-to-track BEV distance at one instant; infinity outside the gate.
  double predictedDistance(const Candidate& c, const Track& track, double dt, double now) const;
  // Associate: det_to_track[k] = index into tracks_ of detection k's track, or -1.
  void associate(ObjectClass label, const std::vector<Candidate>& dets, double dt, double now,
                 std::vector<int>& det_to_track);
  // Birth rule: whether an unmatched detection of this score starts a track.
  bool mayBeBorn(ObjectClass label, double score) const;
  // Confirmation rule: whether a tentative track, just matched with this score, is confirmed.
  bool confirms(const Track& track, double score) const;
  // Birth: a new tentative track.
  Track birth(ObjectClass label);
  // Update: a matched or newborn track takes the detection.
  void updateTrack(Track& track, const Candidate& c, double stamp, const float* feature, std::size_t feature_dim);
  // Output: the detection with the confirmed track's id (and velocity) into frame.
  void emit(const Track& track, const Candidate& c, const Box& detection, const Eigen::Matrix3d& R,
            FrameOutput& frame) const;
  // Age: unmatched tracks coast or end.
  void ageTracks(const std::vector<char>& track_matched, double dt);
  // Least-squares velocity over the last velocity_window centres of the history plus `current`; false if too few.
  bool estimateVelocity(const TrackHistory& history, const Eigen::Vector3d& current, double stamp,
                        Eigen::Vector2d& velocity) const;

  TrackerOptions options_;
  std::vector<Track> tracks_;
  std::uint32_t next_id_ = 1;
  bool has_stamp_ = false;
  double last_stamp_ = 0.0;
  Eigen::Isometry3d last_sensor_to_fixed_ = Eigen::Isometry3d::Identity();
  std::size_t num_resets_ = 0;
  std::size_t feature_dim_ = 0;  // of the features in the tracks' histories
  bool warned_unknown_class_ = false;
};

}  // namespace ret3d
