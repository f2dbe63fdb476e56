// The greedy tracker's histories, velocity estimate, detection features, option checks and a benchmark of 50 tracks.
#include "ret3d/tracking/greedy_tracker.h"

#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <random>

#include "support/tracker_scenes.h"

namespace ret3d {
namespace {

using namespace test;

TEST(GreedyTracker, HistoryMovedIntoTheSensorFrameByHand) {
  GreedyTracker tracker{TrackerOptions()};
  // Frame 0 (t = 10.0): ego at the origin; a car without detector velocity at sensor (5, 0), heading 0.
  Box d0 = Actor{ObjectClass::Car, 5, 0, 0, 0}.at(0);
  d0.vx = d0.vy = 0;
  d0.yaw = 0;
  const auto out0 = tracker.update({d0}, 10.0, Eigen::Isometry3d::Identity());
  ASSERT_EQ(out0.size(), 1u);
  const std::uint32_t id = out0[0].track_id;
  // Frame 1 (t = 10.1): the ego stands at (1, 0) facing +y; the car has moved to fixed (5.5, 0.2), heading 0.1,
  // which is sensor (0.2, -4.5) (fixed offset (4.5, 0.2) rotated by -90 deg), heading 0.1 - pi/2.
  const Eigen::Isometry3d pose1 = makeTransform(1, 0, 0, M_PI / 2);
  Box d1 = d0;
  d1.x = 0.2;
  d1.y = -4.5;
  d1.yaw = 0.1 - M_PI / 2;
  const auto out1 = tracker.update({d1}, 10.1, pose1);
  ASSERT_EQ(out1.size(), 1u);
  EXPECT_EQ(out1[0].track_id, id);
  // Estimated velocity: fixed (0.5, 0.2) / 0.1 s = (5, 2) m/s, i.e. sensor (2, -5).
  EXPECT_NEAR(out1[0].vx, 2.0, 1e-9);
  EXPECT_NEAR(out1[0].vy, -5.0, 1e-9);
  const std::vector<TimedBox> h = tracker.history(id);
  ASSERT_EQ(h.size(), 2u);
  // Entry 0: fixed (5, 0), offset (4, 0) from the ego -> sensor (0, -4); heading 0 -> -pi/2; 0.1 s ago; no velocity.
  EXPECT_NEAR(h[0].box.x, 0.0, 1e-9);
  EXPECT_NEAR(h[0].box.y, -4.0, 1e-9);
  EXPECT_NEAR(h[0].box.z, d0.z, 1e-9);
  EXPECT_NEAR(h[0].box.yaw, -M_PI / 2, 1e-9);
  EXPECT_NEAR(h[0].dt, -0.1, 1e-9);
  EXPECT_NEAR(h[0].box.vx, 0.0, 1e-9);
  EXPECT_EQ(h[0].box.track_id, id);
  // Entry 1: this frame's detection, as given.
  EXPECT_NEAR(h[1].box.x, 0.2, 1e-9);
  EXPECT_NEAR(h[1].box.y, -4.5, 1e-9);
  EXPECT_NEAR(h[1].box.yaw, 0.1 - M_PI / 2, 1e-9);
  EXPECT_NEAR(h[1].box.vx, 2.0, 1e-9);
  EXPECT_NEAR(h[1].box.vy, -5.0, 1e-9);
  EXPECT_DOUBLE_EQ(h[1].dt, 0.0);
  // Stored in the fixed frame.
  const TrackHistory* stored = tracker.findHistory(id);
  ASSERT_NE(stored, nullptr);
  EXPECT_NEAR((*stored)[1].box.x, 5.5, 1e-9);
  EXPECT_NEAR((*stored)[1].box.y, 0.2, 1e-9);
  EXPECT_TRUE(tracker.history(id + 100).empty());
}

TEST(GreedyTracker, HistoryKeepsTheLastNBoxes) {
  TrackerOptions o;
  o.history_length = 4;
  GreedyTracker tracker(o);
  const Actor car{ObjectClass::Car, 0, 0, 10, 0};
  std::uint32_t id = 0;
  for (int f = 0; f < 10; ++f) id = tracker.update({car.at(f * kDt)}, f * kDt, Eigen::Isometry3d::Identity())[0].track_id;
  const auto h = tracker.history(id);
  ASSERT_EQ(h.size(), 4u);
  for (int i = 0; i < 4; ++i) {
    EXPECT_NEAR(h[i].dt, -0.1 * (3 - i), 1e-9);
    EXPECT_NEAR(h[i].box.x, 10 * (6 + i) * kDt, 1e-9);
  }
}

TEST(GreedyTracker, EstimatedVelocityIsTheLeastSquaresSlope) {
  TrackerOptions o;
  o.use_detection_velocity = false;
  GreedyTracker tracker(o);
  const Actor car{ObjectClass::Car, 0, 0, 8, -3};  // detector velocity present but ignored
  Box last;
  for (int f = 0; f < 8; ++f) last = tracker.update({car.at(f * kDt)}, f * kDt, Eigen::Isometry3d::Identity())[0];
  EXPECT_NEAR(last.vx, 8.0, 1e-9);
  EXPECT_NEAR(last.vy, -3.0, 1e-9);
}

TEST(GreedyTracker, DetectionFeaturesFollowTheirBoxesIntoOutputAndHistory) {
  GreedyTracker tracker{TrackerOptions()};
  const Actor a{ObjectClass::Car, 10, 0, 10, 0}, b{ObjectClass::Pedestrian, 5, 5, 1, 0};
  std::uint32_t id_b = 0;
  for (int f = 0; f < 3; ++f) {
    Detections d;
    d.feature_dim = 2;
    Box low = a.at(f * kDt);
    low.y += 20;
    low.score = 0.05f;  // below score_threshold: not output, its feature row must not be either
    d.boxes = {a.at(f * kDt), low, b.at(f * kDt)};
    d.features = {1.0f + f, 2.0f, 99, 99, 3.0f + f, 4.0f};
    const Detections out = tracker.update(d, f * kDt, Eigen::Isometry3d::Identity());
    ASSERT_EQ(out.size(), 2u);
    ASSERT_EQ(out.feature_dim, 2u);
    ASSERT_EQ(out.features.size(), 4u);
    EXPECT_EQ(out.boxes[0].label, ObjectClass::Car);
    EXPECT_FLOAT_EQ(out.feature(0)[0], 1.0f + f);
    EXPECT_FLOAT_EQ(out.feature(1)[0], 3.0f + f);
    id_b = out.boxes[1].track_id;
  }
  const TrackHistory* h = tracker.findHistory(id_b);
  ASSERT_NE(h, nullptr);
  ASSERT_EQ(h->size(), 3u);
  ASSERT_EQ(h->featureDim(), 2u);
  for (std::size_t i = 0; i < 3; ++i) EXPECT_FLOAT_EQ(h->feature(i)[0], 3.0f + i);

  // Another producer's feature size: a reset with one log line, then tracking goes on.
  LogCapture log;
  Detections d;
  d.feature_dim = 3;
  d.boxes = {a.at(0.3)};
  d.features = {1, 2, 3};
  const Detections out = tracker.update(d, 0.3, Eigen::Isometry3d::Identity());
  ASSERT_EQ(out.size(), 1u);
  EXPECT_GT(out.boxes[0].track_id, id_b);
  EXPECT_EQ(tracker.numResets(), 1u);
  EXPECT_EQ(log.lines.size(), 1u);
  // An empty frame without features is no change of producer.
  EXPECT_TRUE(tracker.update(Detections(), 0.4, Eigen::Isometry3d::Identity()).empty());
  EXPECT_EQ(tracker.numTracks(), 1u);
  d.boxes = {a.at(0.5)};
  EXPECT_EQ(tracker.update(d, 0.5, Eigen::Isometry3d::Identity()).boxes[0].track_id, out.boxes[0].track_id);
  EXPECT_EQ(tracker.numResets(), 1u);
  Detections bad = d;
  bad.features.pop_back();
  EXPECT_THROW(tracker.update(bad, 0.6, Eigen::Isometry3d::Identity()), std::invalid_argument);
}

TEST(GreedyTracker, RejectsInvalidOptionsAndStamps) {
  TrackerOptions o;
  o.max_age = -2;
  EXPECT_THROW(GreedyTracker{o}, std::invalid_argument);
  GreedyTracker tracker{TrackerOptions()};
  EXPECT_THROW(tracker.update(std::vector<Box>(), std::nan(""), Eigen::Isometry3d::Identity()), std::invalid_argument);
}

// Time per update() for 50 tracks with the default history length (median of 300 frames after the histories are
// full), plus the 50 history() calls InterRM makes per frame. Printed, never asserted.
TEST(GreedyTrackerBenchmark, FiftyTracksDefaultHistory) {
  std::mt19937 rng(1);
  std::uniform_real_distribution<double> u(0, 1);
  std::vector<Actor> actors;
  for (int i = 0; i < 50; ++i) {
    const ObjectClass c = i < 30 ? ObjectClass::Car : i < 42 ? ObjectClass::Pedestrian : ObjectClass::Cyclist;
    const double speed = c == ObjectClass::Car ? 15 : c == ObjectClass::Pedestrian ? 1.4 : 5;
    const double h = u(rng) * 2 * M_PI;
    actors.push_back({c, u(rng) * 100 - 50, u(rng) * 100 - 50, speed * std::cos(h), speed * std::sin(h)});
  }
  for (AssignmentMethod m : {AssignmentMethod::Greedy, AssignmentMethod::Hungarian}) {
    GreedyTracker tracker(optionsFor(m));
    std::vector<double> update_us, history_us;
    std::size_t sink = 0;
    for (int f = 0; f < 340; ++f) {
      const double t = f * kDt;
      const Eigen::Isometry3d pose = makeTransform(10.0 * t, 0, 0, 0.02 * t);
      std::vector<Box> dets;
      for (const Actor& a : actors) dets.push_back(detect(a.at(t), pose, true, 0.05, &rng));
      const auto t0 = std::chrono::steady_clock::now();
      const std::vector<Box> out = tracker.update(dets, t, pose);
      const auto t1 = std::chrono::steady_clock::now();
      for (const Box& b : out) sink += tracker.history(b.track_id).size();
      const auto t2 = std::chrono::steady_clock::now();
      if (f >= 40) {
        update_us.push_back(std::chrono::duration<double, std::micro>(t1 - t0).count());
        history_us.push_back(std::chrono::duration<double, std::micro>(t2 - t1).count());
      }
      if (f == 339) {
        EXPECT_EQ(out.size(), 50u);
      }
    }
    std::nth_element(update_us.begin(), update_us.begin() + update_us.size() / 2, update_us.end());
    std::nth_element(history_us.begin(), history_us.begin() + history_us.size() / 2, history_us.end());
    std::printf("[ bench    ] %s, 50 tracks, history %d: update() median %.1f us; 50 history() calls median %.1f us "
                "(%zu entries)\n",
                assignmentName(m), tracker.options().history_length, update_us[update_us.size() / 2],
                history_us[history_us.size() / 2], sink);
  }
}

}  // namespace
}  // namespace ret3d
