// Offboard track smoothing for pseudo-labels (`ret3d autolabel`): with a whole sequence at hand, every track is
// refined with its past AND future boxes, as offboard auto-labelling does: one robust size per track (a rigid object
// does not change size), centres from a robust local constant-velocity fit, headings smoothed as circular quantities
// with the 180-degree ambiguity resolved by the motion (moving tracks) or by the track's dominant heading (static
// ones), short gaps filled, and weak or short tracks dropped.
#pragma once

#include <cstddef>
#include <vector>

#include "ret3d/core/types.h"

namespace ret3d {

struct TrackSmoothingOptions {
  // Tracks seen in fewer frames than this are dropped (they are mostly false positives or too short to smooth).
  int min_track_length = 3;
  // Tracks whose mean detection score is below this are dropped.
  double min_track_score = 0.3;
  // Half width k of the sliding window (frames t-k .. t+k) of the constant-velocity centre fit and heading mean.
  int half_window = 5;
  // Missed frames inside a track up to this many in a row are filled by the fit (interpolation); longer gaps are
  // left empty.
  int max_gap = 5;
  // Observations farther than this (m) from the window's first fit are left out of the refit (outliers).
  double outlier_distance = 1.0;
  // A track whose median fitted speed is above this (m/s) is moving: in its frames faster than this, the heading
  // agrees with the direction of motion; in the others, and on static tracks, with the track's dominant heading.
  double moving_speed = 1.0;
  // Size: the median over this fraction of the track's observations with the most points (then the highest score).
  double size_fraction = 0.5;
  // Time between frames (s), for velocities and the moving test.
  double frame_period = 0.1;
};

struct TrackSmoothingStats {
  std::size_t tracks_in = 0, tracks_kept = 0, dropped_short = 0, dropped_score = 0;
  std::size_t boxes_in = 0, boxes_out = 0, boxes_filled = 0;  // boxes_filled: added in gaps
};

// `frames[t]`: the tracked boxes of frame t in one fixed (world) frame, each with its track id (boxes with id 0 are
// ignored). Returns per frame the smoothed boxes of the kept tracks, in the same frame and with the same ids: size,
// centre, heading, velocity (from the fit) smoothed, class the track's (score-weighted) majority, score the track's
// mean score, num_points the observation's (0 in filled gaps). Throws std::invalid_argument for invalid options.
std::vector<std::vector<Box>> smoothTracks(const std::vector<std::vector<Box>>& frames,
                                           const TrackSmoothingOptions& options = {},
                                           TrackSmoothingStats* stats = nullptr);

}  // namespace ret3d
