#include "ret3d/tracking/track_smoothing.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>

#include "ret3d/core/geometry.h"

namespace ret3d {
namespace {

constexpr int kFrames = 30;
constexpr int kMissing = 12;  // the car's missed frame
constexpr double kSpeed = 8.0;  // m/s
const double kDirection = 0.6;  // rad: the car drives along this heading

Box truthAt(int f) {
  Box b;
  b.x = 5.0 + kSpeed * 0.1 * f * std::cos(kDirection);
  b.y = -3.0 + kSpeed * 0.1 * f * std::sin(kDirection);
  b.z = -0.8;
  b.length = 4.2, b.width = 1.8, b.height = 1.6;
  b.yaw = kDirection;
  b.label = ObjectClass::Car;
  b.track_id = 1;
  return b;
}

// The car seen with noisy centres (sigma 0.2 m), noisy sizes, small heading noise and every fourth heading flipped by
// 180 degrees, frame kMissing missed; a 2-frame false track (id 2).
std::vector<std::vector<Box>> noisyFrames(std::vector<std::vector<Box>>* truth) {
  std::mt19937 rng(7);
  std::normal_distribution<double> centre(0.0, 0.2), size(0.0, 0.15), heading(0.0, 0.05);
  std::uniform_real_distribution<double> score(0.5, 0.9);
  std::vector<std::vector<Box>> frames(kFrames);
  truth->assign(kFrames, {});
  for (int f = 0; f < kFrames; ++f) {
    const Box t = truthAt(f);
    (*truth)[static_cast<std::size_t>(f)].push_back(t);
    if (f == kMissing) continue;
    Box b = t;
    b.x += centre(rng), b.y += centre(rng), b.z += 0.5 * centre(rng);
    b.length += size(rng), b.width += size(rng), b.height += size(rng);
    b.yaw = wrapAngle(b.yaw + heading(rng) + (f % 4 == 1 ? M_PI : 0.0));
    b.score = static_cast<float>(score(rng));
    b.num_points = static_cast<std::uint32_t>(200 - 5 * f);
    frames[static_cast<std::size_t>(f)].push_back(b);
  }
  for (int f = 3; f < 5; ++f) {
    Box ghost = truthAt(0);
    ghost.x = 30, ghost.y = 10, ghost.track_id = 2, ghost.score = 0.9f;
    frames[static_cast<std::size_t>(f)].push_back(ghost);
  }
  return frames;
}

double bevError(const Box& a, const Box& b) { return std::hypot(a.x - b.x, a.y - b.y); }

TEST(TrackSmoothing, MovingCarSmoothedFilledAndShortTrackDropped) {
  std::vector<std::vector<Box>> truth;
  const auto raw = noisyFrames(&truth);
  TrackSmoothingStats stats;
  const auto out = smoothTracks(raw, TrackSmoothingOptions{}, &stats);
  ASSERT_EQ(out.size(), static_cast<std::size_t>(kFrames));
  EXPECT_EQ(stats.tracks_in, 2u);
  EXPECT_EQ(stats.tracks_kept, 1u);
  EXPECT_EQ(stats.dropped_short, 1u);
  EXPECT_EQ(stats.boxes_filled, 1u);

  double raw_error = 0, smooth_error = 0;
  int raw_n = 0;
  for (int f = 0; f < kFrames; ++f) {
    const auto& boxes = out[static_cast<std::size_t>(f)];
    ASSERT_EQ(boxes.size(), 1u) << "frame " << f << ": only the car, in every frame (the gap filled)";
    const Box& b = boxes.front();
    const Box& t = truth[static_cast<std::size_t>(f)].front();
    EXPECT_EQ(b.track_id, 1u);
    EXPECT_EQ(b.label, ObjectClass::Car);
    smooth_error += bevError(b, t);
    for (const Box& r : raw[static_cast<std::size_t>(f)])
      if (r.track_id == 1) raw_error += bevError(r, t), ++raw_n;
    EXPECT_LT(std::abs(wrapAngle(b.yaw - kDirection)), 10.0 * M_PI / 180.0) << "frame " << f;
    // One size along the whole track, near the truth.
    EXPECT_DOUBLE_EQ(b.length, out[0].front().length);
    EXPECT_DOUBLE_EQ(b.width, out[0].front().width);
    EXPECT_DOUBLE_EQ(b.height, out[0].front().height);
    EXPECT_NEAR(b.length, t.length, 0.15);
    EXPECT_NEAR(b.width, t.width, 0.15);
    EXPECT_NEAR(b.height, t.height, 0.15);
    EXPECT_NEAR(std::hypot(b.vx, b.vy), kSpeed, 1.0);
  }
  raw_error /= raw_n;
  smooth_error /= kFrames;
  EXPECT_LT(smooth_error, 0.5 * raw_error) << "raw mean error " << raw_error << " m, smoothed " << smooth_error << " m";
  EXPECT_EQ(out[kMissing].front().num_points, 0u);
  // Every box carries the track's mean score.
  EXPECT_FLOAT_EQ(out[0].front().score, out[kFrames - 1].front().score);
  EXPECT_GT(out[0].front().score, 0.5f);
}

TEST(TrackSmoothing, StaticObjectKeepsItsDominantHeading) {
  std::mt19937 rng(3);
  std::normal_distribution<double> centre(0.0, 0.1), heading(0.0, 0.03);
  const double dominant = -2.5;
  std::vector<std::vector<Box>> frames(20);
  for (int f = 0; f < 20; ++f) {
    Box b = truthAt(0);
    b.x = 12 + centre(rng), b.y = 4 + centre(rng);
    // A quarter of the headings flipped: the majority decides.
    b.yaw = wrapAngle(dominant + heading(rng) + (f % 4 == 0 ? M_PI : 0.0));
    frames[static_cast<std::size_t>(f)].push_back(b);
  }
  const auto out = smoothTracks(frames);
  for (const auto& boxes : out) {
    ASSERT_EQ(boxes.size(), 1u);
    EXPECT_LT(std::abs(wrapAngle(boxes.front().yaw - dominant)), 5.0 * M_PI / 180.0);
    EXPECT_LT(std::hypot(boxes.front().vx, boxes.front().vy), 1.0);
  }
}

// A parked car seen with noisy centres: the one-sided fits at its track's ends are fast by noise alone, and must not
// turn it around.
TEST(TrackSmoothing, NoisyParkedCarIsNotTurnedByItsEnds) {
  std::mt19937 rng(5);
  std::normal_distribution<double> centre(0.0, 0.3), heading(0.0, 0.03);
  const double dominant = 3.1;
  std::vector<std::vector<Box>> frames(16);
  for (int f = 0; f < 16; ++f) {
    Box b = truthAt(0);
    b.x = -8 + centre(rng), b.y = 6 + centre(rng);
    b.yaw = wrapAngle(dominant + heading(rng) + (f % 5 == 0 ? M_PI : 0.0));
    frames[static_cast<std::size_t>(f)].push_back(b);
  }
  const auto out = smoothTracks(frames);
  double fastest = 0;
  for (const auto& boxes : out) {
    ASSERT_EQ(boxes.size(), 1u);
    EXPECT_LT(std::abs(wrapAngle(boxes.front().yaw - dominant)), 5.0 * M_PI / 180.0);
    fastest = std::max(fastest, std::hypot(boxes.front().vx, boxes.front().vy));
  }
  EXPECT_GT(fastest, 1.0) << "the test needs an end fit faster than moving_speed";
}

TEST(TrackSmoothing, DropsWeakTracksAndRejectsBadOptions) {
  std::vector<std::vector<Box>> frames(10);
  for (int f = 0; f < 10; ++f) {
    Box b = truthAt(f);
    b.score = 0.2f;
    frames[static_cast<std::size_t>(f)].push_back(b);
  }
  TrackSmoothingStats stats;
  TrackSmoothingOptions o;
  o.min_track_score = 0.3;
  const auto out = smoothTracks(frames, o, &stats);
  EXPECT_EQ(stats.dropped_score, 1u);
  for (const auto& boxes : out) EXPECT_TRUE(boxes.empty());
  o.min_track_score = 0.1;
  EXPECT_EQ(smoothTracks(frames, o)[0].size(), 1u);
  o.half_window = 0;
  EXPECT_THROW(smoothTracks(frames, o), std::invalid_argument);
}

}  // namespace
}  // namespace ret3d
