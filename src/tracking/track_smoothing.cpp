#include "ret3d/tracking/track_smoothing.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <stdexcept>
#include <string>

#include "ret3d/core/geometry.h"

namespace ret3d {
namespace {

struct Observation {
  int frame;
  Box box;
};

// A local constant-velocity fit p(t) = centre + velocity * (t - t0) (per frame, not per second).
struct LineFit {
  Eigen::Vector3d centre = Eigen::Vector3d::Zero();
  Eigen::Vector3d velocity = Eigen::Vector3d::Zero();  // m per frame
};

LineFit fitLine(const std::vector<const Observation*>& obs, int t0) {
  LineFit fit;
  const double n = static_cast<double>(obs.size());
  if (obs.empty()) return fit;
  double st = 0, stt = 0;
  Eigen::Vector3d sp = Eigen::Vector3d::Zero(), stp = Eigen::Vector3d::Zero();
  for (const Observation* o : obs) {
    const double t = o->frame - t0;
    st += t, stt += t * t, sp += o->box.center(), stp += t * o->box.center();
  }
  const double det = n * stt - st * st;
  if (obs.size() < 2 || det < 1e-9) {
    fit.centre = sp / n;
    return fit;
  }
  fit.velocity = (n * stp - st * sp) / det;
  fit.centre = (sp - fit.velocity * st) / n;
  return fit;
}

// The fit at t0 over the window, refitted without the observations farther than `outlier` (BEV) from the first fit
// when at least two remain: one detection displaced by a merge or a partial view does not drag the centre.
LineFit robustFit(const std::vector<const Observation*>& window, int t0, double outlier) {
  const LineFit first = fitLine(window, t0);
  std::vector<const Observation*> inliers;
  for (const Observation* o : window) {
    const Eigen::Vector3d predicted = first.centre + first.velocity * (o->frame - t0);
    if ((o->box.center() - predicted).head<2>().norm() <= outlier) inliers.push_back(o);
  }
  return inliers.size() >= 2 && inliers.size() < window.size() ? fitLine(inliers, t0) : first;
}

// `yaw` or yaw + pi, whichever is within 90 degrees of `reference`.
double alignTo(double yaw, double reference) {
  return std::cos(yaw - reference) >= 0 ? wrapAngle(yaw) : wrapAngle(yaw + M_PI);
}

// Circular mean of the observations' headings, each first turned to agree with `reference`.
double alignedMean(const std::vector<const Observation*>& obs, double reference) {
  double s = 0, c = 0;
  for (const Observation* o : obs) {
    const double a = alignTo(o->box.yaw, reference);
    s += std::sin(a), c += std::cos(a);
  }
  return s == 0 && c == 0 ? wrapAngle(reference) : std::atan2(s, c);
}

double median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  const std::size_t n = v.size();
  return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

// The size from the best-seen observations: most points first, then highest score.
void robustSize(std::vector<const Observation*> obs, double fraction, Box* out) {
  std::sort(obs.begin(), obs.end(), [](const Observation* a, const Observation* b) {
    if (a->box.num_points != b->box.num_points) return a->box.num_points > b->box.num_points;
    return a->box.score > b->box.score;
  });
  const std::size_t n = std::max<std::size_t>(1, static_cast<std::size_t>(std::lround(fraction * obs.size())));
  std::vector<double> l, w, h;
  for (std::size_t i = 0; i < n; ++i) {
    l.push_back(obs[i]->box.length), w.push_back(obs[i]->box.width), h.push_back(obs[i]->box.height);
  }
  out->length = median(l), out->width = median(w), out->height = median(h);
}

ObjectClass majorityClass(const std::vector<Observation>& obs) {
  std::map<ObjectClass, double> votes;
  for (const Observation& o : obs) votes[o.box.label] += std::max(1e-3, static_cast<double>(o.box.score));
  return std::max_element(votes.begin(), votes.end(), [](const auto& a, const auto& b) { return a.second < b.second; })
      ->first;
}

void validate(const TrackSmoothingOptions& o) {
  auto fail = [](const std::string& what) { throw std::invalid_argument("track smoothing: " + what); };
  if (o.min_track_length < 1) fail("min_track_length must be >= 1, got " + std::to_string(o.min_track_length));
  if (o.half_window < 1) fail("half_window must be >= 1, got " + std::to_string(o.half_window));
  if (o.max_gap < 0) fail("max_gap must be >= 0, got " + std::to_string(o.max_gap));
  if (!(o.outlier_distance > 0)) fail("outlier_distance must be > 0, got " + std::to_string(o.outlier_distance));
  if (!(o.size_fraction > 0 && o.size_fraction <= 1))
    fail("size_fraction must be in (0, 1], got " + std::to_string(o.size_fraction));
  if (!(o.frame_period > 0)) fail("frame_period must be > 0, got " + std::to_string(o.frame_period));
}

// Every track's observations in frame order, one box per track and frame (the best-scored one); boxes without a track
// id are left out.
std::map<std::uint32_t, std::vector<Observation>> collectTracks(const std::vector<std::vector<Box>>& frames,
                                                                TrackSmoothingStats& st) {
  std::map<std::uint32_t, std::vector<Observation>> tracks;
  for (int f = 0; f < static_cast<int>(frames.size()); ++f) {
    for (const Box& b : frames[static_cast<std::size_t>(f)]) {
      if (b.track_id == 0) continue;
      ++st.boxes_in;
      auto& obs = tracks[b.track_id];
      if (!obs.empty() && obs.back().frame == f) {
        if (b.score > obs.back().box.score) obs.back().box = b;
        continue;
      }
      obs.push_back({f, b});
    }
  }
  st.tracks_in = tracks.size();
  return tracks;
}

// The frames to label: every observed one, and the missed ones in gaps of at most max_gap frames.
std::vector<int> targetFrames(const std::vector<Observation>& obs, int max_gap) {
  std::vector<int> targets;
  for (std::size_t i = 0; i < obs.size(); ++i) {
    targets.push_back(obs[i].frame);
    if (i + 1 < obs.size() && obs[i + 1].frame - obs[i].frame - 1 <= max_gap)
      for (int f = obs[i].frame + 1; f < obs[i + 1].frame; ++f) targets.push_back(f);
  }
  return targets;
}

// One target frame's centre and velocity fit over the observations within half_window frames of it.
struct FrameFit {
  int frame;
  LineFit fit;
  std::vector<const Observation*> window;
  const Observation* seen;  // null in a filled gap
};

// The fits of the target frames, with each fit's speed and the summed motion directions of the moving ones (to
// orient the dominant heading).
struct TrackMotion {
  std::vector<FrameFit> fits;
  std::vector<double> speeds;
  double motion_s = 0, motion_c = 0;
};

TrackMotion fitFrames(const std::vector<Observation>& obs, const std::vector<int>& targets,
                      const TrackSmoothingOptions& opt) {
  TrackMotion m;
  for (const int t : targets) {
    FrameFit fr{t, {}, {}, nullptr};
    const Observation* before = nullptr;
    const Observation* after = nullptr;
    for (const Observation& o : obs) {
      if (std::abs(o.frame - t) <= opt.half_window) fr.window.push_back(&o);
      if (o.frame == t) fr.seen = &o;
      if (o.frame < t) before = &o;
      if (o.frame > t && !after) after = &o;
    }
    // A gap wider than the window: interpolate between its ends.
    if (fr.window.size() < 2 && !fr.seen && before && after) fr.window = {before, after};
    fr.fit = robustFit(fr.window, t, opt.outlier_distance);
    const Eigen::Vector2d v = fr.fit.velocity.head<2>() / opt.frame_period;
    m.speeds.push_back(v.norm());
    if (v.norm() > opt.moving_speed) m.motion_s += v.y() / v.norm(), m.motion_c += v.x() / v.norm();
    m.fits.push_back(std::move(fr));
  }
  return m;
}

// The dominant heading: the axis of all observed headings (doubled-angle mean, score-weighted), pointing the way the
// track moves when it moves, else the way most of its observations point.
double dominantHeading(const std::vector<Observation>& obs, const std::vector<const Observation*>& all,
                       const TrackMotion& m, bool moving) {
  double s2 = 0, c2 = 0;
  for (const Observation& o : obs)
    s2 += o.box.score * std::sin(2 * o.box.yaw), c2 += o.box.score * std::cos(2 * o.box.yaw);
  const double axis = 0.5 * std::atan2(s2, c2);
  double vote = 0;
  if (moving) {
    vote = std::cos(std::atan2(m.motion_s, m.motion_c) - axis);
  } else {
    for (const Observation& o : obs) vote += o.box.score * (std::cos(o.box.yaw - axis) >= 0 ? 1.0 : -1.0);
  }
  return alignedMean(all, vote >= 0 ? axis : axis + M_PI);
}

// One kept track's smoothed boxes into `out`: a robust size and the majority class for all, per target frame the
// fitted centre and velocity, and the heading of its motion (moving) or the dominant one.
void smoothTrack(std::uint32_t id, const std::vector<Observation>& obs, double score, const TrackSmoothingOptions& opt,
                 std::vector<std::vector<Box>>& out, TrackSmoothingStats& st) {
  std::vector<const Observation*> all;
  for (const Observation& o : obs) all.push_back(&o);
  Box shape = obs.front().box;
  robustSize(all, opt.size_fraction, &shape);
  shape.label = majorityClass(obs);
  shape.score = static_cast<float>(score);
  shape.track_id = id;

  const TrackMotion m = fitFrames(obs, targetFrames(obs, opt.max_gap), opt);
  // Moving as a whole, by the median speed: a parked car's fit at the ends of its track can be fast by noise alone
  // (one-sided windows), and its motion must not turn it around.
  const bool moving = median(m.speeds) > opt.moving_speed;
  const double dominant = dominantHeading(obs, all, m, moving);
  for (const FrameFit& fr : m.fits) {
    Box b = shape;
    b.x = fr.fit.centre.x(), b.y = fr.fit.centre.y(), b.z = fr.fit.centre.z();
    const Eigen::Vector2d v = fr.fit.velocity.head<2>() / opt.frame_period;
    b.vx = v.x(), b.vy = v.y();
    if (moving && v.norm() > opt.moving_speed)
      b.yaw = alignedMean(fr.window, std::atan2(v.y(), v.x()));
    else
      b.yaw = moving ? alignedMean(fr.window, dominant) : dominant;
    b.num_points = fr.seen ? fr.seen->box.num_points : 0;
    if (!fr.seen) ++st.boxes_filled;
    out[static_cast<std::size_t>(fr.frame)].push_back(b);
    ++st.boxes_out;
  }
}

}  // namespace

std::vector<std::vector<Box>> smoothTracks(const std::vector<std::vector<Box>>& frames,
                                           const TrackSmoothingOptions& opt, TrackSmoothingStats* stats) {
  validate(opt);
  TrackSmoothingStats st;
  const std::map<std::uint32_t, std::vector<Observation>> tracks = collectTracks(frames, st);
  std::vector<std::vector<Box>> out(frames.size());
  for (const auto& [id, obs] : tracks) {
    double score = 0;
    for (const Observation& o : obs) score += o.box.score;
    score /= static_cast<double>(obs.size());
    if (static_cast<int>(obs.size()) < opt.min_track_length) {
      ++st.dropped_short;
      continue;
    }
    if (score < opt.min_track_score) {
      ++st.dropped_score;
      continue;
    }
    ++st.tracks_kept;
    smoothTrack(id, obs, score, opt, out, st);
  }
  if (stats) *stats = st;
  return out;
}

}  // namespace ret3d
