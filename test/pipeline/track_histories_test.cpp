// The tracked sequences InterRM gets, online (InterRM nodelet) and offline (TrackRefiner) alike: order and length,
// ageing after the tracker's max_age, ids that end, stamps going backwards; and that they are the tracker's own
// histories when fed the tracker's output.
#include "ret3d/pipeline/track_histories.h"

#include <cmath>
#include <stdexcept>

#include <gtest/gtest.h>

#include "ret3d/core/transform.h"
#include "ret3d/tracking/greedy_tracker.h"

namespace ret3d {
namespace pipeline {
namespace {

Box carAt(double x, double y, std::uint32_t id) {
  Box b;
  b.x = x, b.y = y, b.z = -0.8, b.length = 4, b.width = 1.7, b.height = 1.5, b.yaw = 0.2;
  b.vx = 10.0;
  b.label = ObjectClass::Car;
  b.score = 0.9f;
  b.track_id = id;
  return b;
}

Eigen::Isometry3d egoAt(double x) { return makeTransform(x, 0, 0, 0.3); }

// The box of a car at fixed-frame x = 10 m/s * t, y = 5, seen from the ego at egoAt(5 t).
Box carSeen(double t, std::uint32_t id) {
  Box fixed = carAt(10.0 * t, 5.0, id);
  return transformBox(fixed, egoAt(5.0 * t).inverse());
}

TEST(TrackHistories, SequencesAreNewestFirstInTheCurrentSensorFrameAndCappedAtTheLength) {
  TrackHistories h(4, 5);
  for (int f = 0; f < 7; ++f) {
    const double t = 0.1 * f;
    const std::vector<Box> tracked = {carSeen(t, 7)};
    const TrackHistories::Sequences s = h.update(tracked, t, egoAt(5.0 * t));
    ASSERT_EQ(s.sequences.size(), 1u);
    ASSERT_EQ(s.rows, std::vector<std::size_t>{0});
    const relation::InterRMSequence& seq = s.sequences[0];
    ASSERT_EQ(seq.boxes.size(), std::min<std::size_t>(f + 1, 4)) << "frame " << f;
    ASSERT_EQ(seq.dt.size(), seq.boxes.size());
    // The current box exactly as tracked, not through the fixed frame and back.
    EXPECT_EQ(seq.boxes[0].x, tracked[0].x);
    EXPECT_EQ(seq.boxes[0].y, tracked[0].y);
    EXPECT_EQ(seq.boxes[0].yaw, tracked[0].yaw);
    EXPECT_EQ(seq.dt[0], 0.0);
    for (std::size_t k = 1; k < seq.boxes.size(); ++k) {
      // Entry k is k frames back, moved into this frame's sensor frame.
      const Box expected = transformBox(carAt(10.0 * (t - 0.1 * k), 5.0, 7), egoAt(5.0 * t).inverse());
      EXPECT_NEAR(seq.dt[k], -0.1 * k, 1e-12);
      EXPECT_NEAR(seq.boxes[k].x, expected.x, 1e-9) << "frame " << f << " entry " << k;
      EXPECT_NEAR(seq.boxes[k].y, expected.y, 1e-9);
      EXPECT_NEAR(seq.boxes[k].yaw, expected.yaw, 1e-9);
      EXPECT_NEAR(seq.boxes[k].vx, expected.vx, 1e-9);
      EXPECT_EQ(seq.boxes[k].track_id, 7u);
    }
  }
}

TEST(TrackHistories, BoxesWithoutATrackIdGetNoSequence) {
  TrackHistories h(30, 5);
  const auto s = h.update({carAt(1, 0, 0), carAt(2, 0, 3), carAt(3, 0, 0), carAt(4, 0, 9)}, 0.0, egoAt(0));
  EXPECT_EQ(s.rows, (std::vector<std::size_t>{1, 3}));
  ASSERT_EQ(s.sequences.size(), 2u);
  EXPECT_EQ(s.sequences[1].boxes[0].x, 4.0);
  EXPECT_EQ(h.size(), 2u);
  // The refined boxes go back to their rows; the others stay.
  std::vector<Box> tracked = {carAt(1, 0, 0), carAt(2, 0, 3), carAt(3, 0, 0), carAt(4, 0, 9)};
  applyRefined(s, {carAt(20, 0, 3), carAt(40, 0, 9)}, tracked);
  EXPECT_EQ(tracked[0].x, 1.0);
  EXPECT_EQ(tracked[1].x, 20.0);
  EXPECT_EQ(tracked[2].x, 3.0);
  EXPECT_EQ(tracked[3].x, 40.0);
  EXPECT_THROW(applyRefined(s, {carAt(20, 0, 3)}, tracked), std::invalid_argument);
}

// A track the tracker coasts for up to max_age frames keeps its history; unseen for one frame more, it is gone (the
// tracker has ended it and never hands its id out again), while the tracks still seen keep theirs.
TEST(TrackHistories, AHistoryAgesOutAfterMaxAgeUnseenFrames) {
  const int max_age = 3;
  for (int gap : {max_age, max_age + 1}) {
    TrackHistories h(30, max_age);
    int f = 0;
    for (; f < 5; ++f) h.update({carSeen(0.1 * f, 1), carSeen(0.1 * f, 2)}, 0.1 * f, egoAt(0.5 * f));
    // Track 1 unseen for `gap` frames, track 2 seen throughout.
    for (int k = 0; k < gap; ++k, ++f) h.update({carSeen(0.1 * f, 2)}, 0.1 * f, egoAt(0.5 * f));
    if (gap <= max_age) {
      ASSERT_NE(h.find(1), nullptr) << "gap " << gap;
      EXPECT_EQ(h.find(1)->size(), 5u);
      // When it comes back its sequence holds its past boxes: 5 before the gap and this one.
      const auto s = h.update({carSeen(0.1 * f, 1), carSeen(0.1 * f, 2)}, 0.1 * f, egoAt(0.5 * f));
      EXPECT_EQ(s.sequences[0].boxes.size(), 6u);
      EXPECT_NEAR(s.sequences[0].dt.back(), -0.1 * f, 1e-9);  // frame 0's box
    } else {
      EXPECT_EQ(h.find(1), nullptr) << "gap " << gap;
      EXPECT_EQ(h.size(), 1u);
    }
    ASSERT_NE(h.find(2), nullptr);
    EXPECT_EQ(h.find(2)->size(), static_cast<std::size_t>(f + (gap <= max_age ? 1 : 0)));
  }
}

// An id that ends is not reused by the tracker: the next object gets a new id and a history of its own, never the
// ended track's boxes, and the ended id's history is dropped.
TEST(TrackHistories, ANewIdStartsAfreshAfterATrackEnds) {
  TrackHistories h(30, 2);
  int f = 0;
  for (; f < 6; ++f) h.update({carSeen(0.1 * f, 1)}, 0.1 * f, egoAt(0.5 * f));
  for (int k = 0; k < 3; ++k, ++f) EXPECT_TRUE(h.update({}, 0.1 * f, egoAt(0.5 * f)).sequences.empty());
  EXPECT_EQ(h.size(), 0u);
  const auto s = h.update({carSeen(0.1 * f, 2)}, 0.1 * f, egoAt(0.5 * f));
  ASSERT_EQ(s.sequences.size(), 1u);
  EXPECT_EQ(s.sequences[0].boxes.size(), 1u);
  EXPECT_EQ(s.sequences[0].boxes[0].track_id, 2u);
  EXPECT_EQ(h.find(1), nullptr);
}

TEST(TrackHistories, AStampGoingBackwardsClearsEveryHistory) {
  TrackHistories h(30, 5);
  for (int f = 0; f < 3; ++f) EXPECT_FALSE(h.update({carSeen(0.1 * f, 1)}, 0.1 * f, egoAt(0.5 * f)).cleared);
  const auto s = h.update({carSeen(0, 1)}, 0.0, egoAt(0));  // a bag loop
  EXPECT_TRUE(s.cleared);
  EXPECT_EQ(s.sequences[0].boxes.size(), 1u);
  // The same stamp twice keeps one entry for it.
  EXPECT_EQ(h.update({carSeen(0, 1)}, 0.0, egoAt(0)).sequences[0].boxes.size(), 1u);
}

TEST(TrackHistories, InvalidSettingsAreRefused) {
  EXPECT_THROW(TrackHistories(0, 5), std::invalid_argument);
  EXPECT_THROW(TrackHistories(30, -1), std::invalid_argument);
}

// Fed the tracker's output, the sequences hold what the tracker keeps in its own histories: the boxes the tracker
// matched, frame by frame, in the current sensor frame.
TEST(TrackHistories, FedTheTrackersOutputTheyMatchTheTrackersHistories) {
  TrackerOptions o;
  o.max_age = 2;
  GreedyTracker tracker(o);
  TrackHistories h(static_cast<std::size_t>(o.history_length), o.max_age);
  for (int f = 0; f < 40; ++f) {
    const double t = 0.1 * f;
    std::vector<Box> dets;
    for (int i = 0; i < 4; ++i) {
      if (i == 1 && f >= 10 && f < 13) continue;  // missed for 3 frames: its track ends, it comes back with a new id
      if (i == 2 && f % 4 == 3) continue;         // missed every fourth frame: coasts, keeps its id
      Box b = carSeen(t, 0);
      b.y += 6.0 * i;
      dets.push_back(b);
    }
    const Eigen::Isometry3d pose = egoAt(5.0 * t);
    const std::vector<Box> tracked = tracker.update(dets, t, pose);
    const auto s = h.update(tracked, t, pose);
    ASSERT_EQ(s.sequences.size(), tracked.size());
    for (std::size_t k = 0; k < tracked.size(); ++k) {
      const std::vector<TimedBox> own = tracker.history(tracked[k].track_id);  // oldest first
      const relation::InterRMSequence& seq = s.sequences[k];
      ASSERT_EQ(seq.boxes.size(), own.size()) << "frame " << f << " id " << tracked[k].track_id;
      for (std::size_t e = 1; e < own.size(); ++e) {
        const TimedBox& expected = own[own.size() - 1 - e];
        EXPECT_NEAR(seq.boxes[e].x, expected.box.x, 1e-9);
        EXPECT_NEAR(seq.boxes[e].y, expected.box.y, 1e-9);
        EXPECT_NEAR(seq.boxes[e].vx, expected.box.vx, 1e-9);
        EXPECT_NEAR(seq.dt[e], expected.dt, 1e-12);
      }
    }
  }
  EXPECT_EQ(h.size(), tracker.numTracks());  // both end a track after max_age frames unseen
}

}  // namespace
}  // namespace pipeline
}  // namespace ret3d
