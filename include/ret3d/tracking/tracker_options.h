// Options of the greedy tracker (CenterPoint's tracker, Yin et al. CVPR 2021, as used by Ret3D §3.3), loaded from
// YAML by one function and validated. The defaults here and in config/tracker.yaml are the same values; a test keeps
// them in step.
#pragma once

#include <string>

#include "ret3d/core/option_range.h"
#include "ret3d/core/per_class.h"
#include "ret3d/core/types.h"

namespace ret3d {

enum class AssignmentMethod { Greedy, Hungarian };

struct TrackerOptions {
  // Matching: greedy in descending detection score (CenterPoint's default) or optimal (Hungarian, O(n^3)).
  AssignmentMethod assignment = AssignmentMethod::Greedy;

  // Gate on the BEV centre distance (m) between a motion-compensated detection and a track's predicted centre.
  // CenterPoint's published thresholds: Waymo (10 Hz, tools/waymo_tracking/test.py) vehicle 0.8, pedestrian 0.4,
  // cyclist 0.6; nuScenes (2 Hz keyframes, "99.9 percentile of the l2 velocity error per 0.5 s") car 4, pedestrian 1,
  // bicycle 3, i.e. 0.8 / 0.2 / 0.6 when scaled to 0.1 s. Our frames are 10 Hz like Waymo's, so Waymo's values, but
  // 1.0 m for cars: with velocities estimated from noisy boxes (KITTI PointRCNN, 0001-0015) car ID switches were
  // 135 / 105 / 90 / 190 for 0.8 / 1.0 / 1.2 / 1.5 m; 1.0 keeps a margin from that cliff. Pedestrians and cyclists
  // hardly changed between 0.4-1.0 and 0.6-1.5 m.
  PerClass<double> gate{1.0, 0.4, 0.6};
  // Fastest plausible speed (m/s). A track whose velocity is not known yet (one observation, detections without
  // velocity) gets gate + max_speed * (time since it was last seen), since it may have moved that far.
  PerClass<double> max_speed{30.0, 3.0, 10.0};

  // Detections scoring below this are ignored entirely (neither matched nor born).
  double score_threshold = 0.1;
  // An unmatched detection starts a new track only if its score is at least this: CenterPoint's Waymo score_thresh.
  // Lower values start a track for every clutter box (KITTI 0001-0015: 0.5 gives 1.8x the ids of 0.75 and more
  // ID switches); higher ones lose the first frames of real objects. A score is a probability (sigmoid of a logit).
  // Per class (YAML: one number for all, or a map by class): a class whose scores are less calibrated (the LWD-3D
  // detector's cyclists) needs a stricter birth than the others.
  PerClass<double> birth_score{0.75, 0.75, 0.75};
  // Publishing (AB3DMOT's min_hits; a track is "tentative" until confirmed): a track's boxes are output once it is
  // confirmed, either by one detection scoring at least confirm_score (a box the detector itself would publish) or by
  // being matched in min_hits consecutive frames from its birth. A tentative track is matched like any other (its
  // history grows) but not output, and it ends at its first unmatched frame, so a box seen in one frame alone is never
  // published unless it scores confirm_score. Per class (YAML: one number for all, or a map by class). min_hits 1:
  // every track is confirmed at birth.
  PerClass<double> confirm_score{0.0, 0.0, 0.0};
  PerClass<int> min_hits{1, 1, 1};
  // A confirmed track's box is output in a frame only when its detection there scores at least output_score; below,
  // the track is continued (matched, its history grown) without a box. Tracks are kept alive through weak detections
  // (score_threshold), and output_score keeps a persistent false object's weak frames unpublished. Per class (YAML:
  // one number for all, or a map by class); 0: every matched frame.
  PerClass<double> output_score{0.0, 0.0, 0.0};
  // Frames a track may go unmatched and still be matched again; it coasts on its velocity meanwhile and is not output.
  // CenterPoint's Waymo max_age = 3 counts the matched frame too (2 coasting frames; ours counts misses only). On the
  // PointRCNN boxes of KITTI tracking 0001-0015 car ID switches went 179 / 122 / 105 / 99 for 1 / 3 / 5 / 10: 5
  // (0.5 s) takes most of the gain while a coasting track's predicted centre has not drifted far.
  int max_age = 5;
  // A gap between consecutive frames longer than this (s), or any backwards jump, resets the tracker.
  double max_time_gap = 1.0;

  // Use the detector's (vx, vy) when present. Without it (or when a detection's velocity is exactly zero: the
  // "unknown" of detectors without a velocity head), the track's velocity is the least-squares slope of its last
  // velocity_window centres in the fixed frame.
  bool use_detection_velocity = true;
  int velocity_window = 5;

  // Boxes kept per track for InterRM (ring buffer). The paper's sequences average 100 frames on Waymo; at 10 Hz 30
  // entries are 3 s of motion, which bounds InterRM's O(N^2) attention for 50 tracks within the real-time budget.
  // To be revisited by InterRM's ablation over N (the tracker's cost hardly depends on it).
  int history_length = 30;

  // The allowed range of each value (core/option_range.h), checked by validate() alone: YAML, the ROS parameters
  // and the code that builds the struct all go through it.
  static constexpr OptionRange kGate{0, OptionRange::kFinite, true};       // m
  static constexpr OptionRange kMaxSpeed{0, OptionRange::kFinite};         // m/s
  static constexpr OptionRange kScore{-OptionRange::kFinite, OptionRange::kFinite};  // score_threshold, birth, confirm
  static constexpr OptionRange kMinHits{1, 1000};                          // frames
  static constexpr OptionRange kMaxAge{0, 1000};                           // frames
  static constexpr OptionRange kMaxTimeGap{0, OptionRange::kFinite, true}; // s
  static constexpr OptionRange kVelocityWindow{2, 1000};                   // frames
  static constexpr OptionRange kHistoryLength{1, 100000};                  // boxes
};

// Reads options from a YAML file: a map of the keys above (unknown keys are errors, so typos fail loudly); absent keys
// keep their defaults. Throws std::invalid_argument naming the parameter, its value and what is allowed; a file that
// cannot be read or parsed throws std::runtime_error naming the file.
TrackerOptions loadTrackerOptions(const std::string& yaml_path);
// The same from YAML text.
TrackerOptions parseTrackerOptions(const std::string& yaml_text);
// Throws OptionError (a std::invalid_argument) for the first value outside its range, naming its key.
void validate(const TrackerOptions& options);

const char* assignmentName(AssignmentMethod m);

}  // namespace ret3d
