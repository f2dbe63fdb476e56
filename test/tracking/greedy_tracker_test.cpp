#include "ret3d/tracking/greedy_tracker.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <functional>
#include <cmath>
#include <map>
#include <random>
#include <set>
#include <string>

#include "ret3d/core/log.h"
#include "ret3d/core/transform.h"

#include "support/tracker_scenes.h"

namespace ret3d {
namespace {

using namespace test;

class TrackerModes : public ::testing::TestWithParam<std::tuple<AssignmentMethod, bool>> {
 protected:
  AssignmentMethod method() const { return std::get<0>(GetParam()); }
  bool withVelocity() const { return std::get<1>(GetParam()); }
  std::string name() const {
    return std::string(assignmentName(method())) + (withVelocity() ? ", detector velocity" : ", estimated velocity");
  }
};

TEST_P(TrackerModes, ConstantVelocityObjectsKeepTheirIds) {
  const std::vector<Actor> actors = {
      {ObjectClass::Car, 10, 0, 15, 0},         {ObjectClass::Car, 20, 3.5, -12, 0},
      {ObjectClass::Car, 5, -7, 8, 6},          {ObjectClass::Car, 30, -3.5, 0, 0},
      {ObjectClass::Pedestrian, 8, 6, 0, 1.4},  {ObjectClass::Pedestrian, 9, 6, 1.2, -0.3},
      {ObjectClass::Cyclist, 15, 8, -5, 0},
  };
  GreedyTracker tracker(optionsFor(method(), withVelocity()));
  // 5 cm centre noise: typical of a good detector's localisation.
  const auto ids = run(tracker, actors, 60, withVelocity(), 0.05);
  expectOneIdPerActor(ids, name());
  EXPECT_EQ(tracker.lastId(), actors.size());
}

TEST_P(TrackerModes, CrossingObjectsKeepTheirIds) {
  // Two cars on perpendicular roads pass the same point 0.15 s apart (10 m/s): their centres come within 1.06 m,
  // about the car gate; two pedestrians walk through each other's path 0.2 s apart, 0.2 m at the closest.
  const std::vector<Actor> actors = {
      {ObjectClass::Car, 20 - 20, 10, 10, 0},      // reaches (20, 10) at t = 2.0
      {ObjectClass::Car, 20, 10 - 21.5, 0, 10},    // reaches (20, 10) at t = 2.15
      {ObjectClass::Pedestrian, 5 - 3, 4, 1.5, 0},  // reaches (5, 4) at t = 2.0
      {ObjectClass::Pedestrian, 5 + 3.3, 4.2, -1.5, 0},  // reaches (5, 4.2) at t = 2.2
  };
  GreedyTracker tracker(optionsFor(method(), withVelocity()));
  const auto ids = run(tracker, actors, 45, withVelocity(), 0.02);
  expectOneIdPerActor(ids, name());
}

INSTANTIATE_TEST_SUITE_P(All, TrackerModes,
                         ::testing::Combine(::testing::Values(AssignmentMethod::Greedy, AssignmentMethod::Hungarian),
                                            ::testing::Bool()));

// An object missed for `gap` frames in the middle of 40 frames: the id it has afterwards, and its id before.
std::pair<std::uint32_t, std::uint32_t> idsAroundGap(int gap, bool with_velocity, int max_age) {
  TrackerOptions o;
  o.max_age = max_age;
  GreedyTracker tracker(o);
  const Actor car{ObjectClass::Car, 0, 0, 12, 1};
  const Actor other{ObjectClass::Car, 0, 20, -9, 0};  // keeps frames non-empty
  std::uint32_t before = 0, after = 0;
  for (int f = 0; f < 40; ++f) {
    const double t = f * kDt;
    const bool hidden = f >= 20 && f < 20 + gap;
    std::vector<Box> dets = {detect(other.at(t), Eigen::Isometry3d::Identity(), with_velocity)};
    if (!hidden) dets.push_back(detect(car.at(t), Eigen::Isometry3d::Identity(), with_velocity));
    const std::vector<Box> out = tracker.update(dets, t, Eigen::Isometry3d::Identity());
    EXPECT_EQ(out.size(), dets.size());  // the coasting track is not output
    if (hidden) {
      EXPECT_EQ(tracker.numTracks(), f < 20 + max_age ? 2u : 1u) << "frame " << f;
      continue;
    }
    const std::uint32_t id = out.back().track_id;
    if (f == 19) before = id;
    if (f == 20 + gap) after = id;
    if (f > 20 + gap) {
      EXPECT_EQ(id, after);
    }
  }
  return {before, after};
}

TEST(GreedyTracker, GapShorterThanMaxAgeKeepsTheId) {
  for (bool v : {true, false}) {
    for (int max_age : {1, 3, 5}) {
      for (int gap = 1; gap <= max_age; ++gap) {
        const auto [before, after] = idsAroundGap(gap, v, max_age);
        EXPECT_NE(before, 0u);
        EXPECT_EQ(after, before) << "gap " << gap << " max_age " << max_age << " velocity " << v;
      }
    }
  }
}

TEST(GreedyTracker, GapLongerThanMaxAgeGivesANewId) {
  for (bool v : {true, false}) {
    for (int max_age : {0, 1, 3, 5}) {
      const auto [before, after] = idsAroundGap(max_age + 1, v, max_age);
      EXPECT_NE(before, 0u);
      EXPECT_NE(after, 0u);
      EXPECT_GT(after, before) << "max_age " << max_age << " velocity " << v;
    }
  }
}

TEST(GreedyTracker, StaticObjectsKeepIdsWhileTheEgoDrivesAt15ms) {
  // The ego drives at 15 m/s along a gentle curve (yaw rate 0.1 rad/s) past parked cars, a standing pedestrian and a
  // parked bicycle: in the sensor frame they sweep by at 15 m/s, in the fixed frame they stand still.
  auto ego = [](double t) {
    const double yaw = 0.1 * t;
    const double r = 15.0 / 0.1;  // turning radius
    return makeTransform(r * std::sin(yaw), r * (1 - std::cos(yaw)), 0.0, yaw);
  };
  std::vector<Actor> actors;
  for (int i = 0; i < 8; ++i) actors.push_back({ObjectClass::Car, 10.0 + 6.0 * i, -4.0 + 0.3 * i, 0, 0});
  actors.push_back({ObjectClass::Pedestrian, 25, 5, 0, 0});
  actors.push_back({ObjectClass::Cyclist, 40, 6, 0, 0});
  for (bool with_velocity : {true, false}) {
    for (AssignmentMethod m : {AssignmentMethod::Greedy, AssignmentMethod::Hungarian}) {
      GreedyTracker tracker(optionsFor(m));
      // 2 s: the ego covers 30 m, so most objects pass beside it; 5 cm noise.
      const auto ids = run(tracker, actors, 21, with_velocity, 0.05, ego);
      expectOneIdPerActor(ids, std::string(assignmentName(m)) + (with_velocity ? " velocity" : " no velocity"));
    }
  }
}

TEST(GreedyTracker, TrackingInTheSensorFrameWouldLoseStaticObjects) {
  // The control of the test above: with identity poses the same scene's pedestrian moves 1.5 m per frame in the
  // sensor frame, beyond its gate once its (sensor-frame) velocity estimate is noisy. Shows the poses matter.
  auto ego = [](double t) { return makeTransform(15.0 * t, 0, 0, 0.0); };
  const Actor ped{ObjectClass::Pedestrian, 25, 2, 0, 0};
  GreedyTracker tracker{TrackerOptions()};
  std::set<std::uint32_t> ids;
  std::mt19937 rng(5);
  for (int f = 0; f < 15; ++f) {
    const double t = f * kDt;
    const Box d = detect(ped.at(t), ego(t), false, 0.05, &rng);
    for (const Box& b : tracker.update({d}, t, Eigen::Isometry3d::Identity())) ids.insert(b.track_id);
  }
  EXPECT_GT(ids.size(), 1u);
}

TEST(GreedyTracker, BagLoopResetsCleanlyWithOneLogLine) {
  const std::vector<Actor> actors = {{ObjectClass::Car, 10, 0, 10, 0}, {ObjectClass::Pedestrian, 5, 3, 1, 0}};
  GreedyTracker tracker{TrackerOptions()};
  LogCapture log;
  // A bag of 3 s starting at a realistic epoch stamp, played twice (rosbag play -l).
  const double t0 = 1.7e9;
  const auto first = run(tracker, actors, 30, true, 0.0, nullptr, t0);
  expectOneIdPerActor(first, "first play");
  EXPECT_EQ(tracker.numResets(), 0u);
  EXPECT_TRUE(log.lines.empty());
  const std::uint32_t last_before = tracker.lastId();
  const auto second = run(tracker, actors, 30, true, 0.0, nullptr, t0);
  expectOneIdPerActor(second, "second play");
  EXPECT_EQ(tracker.numResets(), 1u);
  ASSERT_EQ(log.lines.size(), 1u);
  EXPECT_NE(log.lines[0].find("reset"), std::string::npos) << log.lines[0];
  EXPECT_GT(second[0][0], last_before);  // new ids, none reused
  EXPECT_GT(second[1][0], last_before);
  EXPECT_EQ(tracker.numTracks(), actors.size());  // the first play's tracks are gone
}

TEST(GreedyTracker, LongGapResets) {
  const std::vector<Actor> actors = {{ObjectClass::Car, 10, 0, 10, 0}};
  TrackerOptions o;
  o.max_time_gap = 0.5;
  GreedyTracker tracker(o);
  LogCapture log;
  const auto a = run(tracker, actors, 5, true);
  const auto b = run(tracker, actors, 5, true, 0.0, nullptr, 0.4 + 0.45);  // 0.45 s gap: no reset
  EXPECT_EQ(b[0][0], a[0][0]);
  EXPECT_EQ(tracker.numResets(), 0u);
  const auto c = run(tracker, actors, 5, true, 0.0, nullptr, 1.25 + 0.6);  // 0.6 s gap: reset
  EXPECT_GT(c[0][0], b[0][0]);
  EXPECT_EQ(tracker.numResets(), 1u);
  EXPECT_EQ(log.lines.size(), 1u);
}

TEST(GreedyTracker, IdsAreNeverReused) {
  // Objects appear and vanish at random over 400 frames (with two bag loops): every id is new when first output,
  // and once a track has ended its id never comes back.
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> u(0, 1);
  TrackerOptions o;
  o.max_age = 2;
  GreedyTracker tracker(o);
  struct Live {
    Actor a;
    double born;
  };
  std::vector<Live> live;
  std::map<std::uint32_t, int> last_frame;
  std::uint32_t max_seen = 0;
  double t = 0;
  for (int f = 0; f < 400; ++f, t += kDt) {
    if (f == 150 || f == 300) t = 0;  // bag loops
    if (u(rng) < 0.3 && live.size() < 20) {
      const ObjectClass c = kDetectedClasses[static_cast<int>(u(rng) * 3) % 3];
      live.push_back({{c, u(rng) * 80, u(rng) * 80 - 40, u(rng) * 10 - 5, u(rng) * 10 - 5}, t});
    }
    if (!live.empty() && u(rng) < 0.2) {
      const std::size_t k = std::min(live.size() - 1, static_cast<std::size_t>(u(rng) * live.size()));
      live.erase(live.begin() + static_cast<std::ptrdiff_t>(k));
    }
    if (f == 150 || f == 300) {  // after a loop no earlier id may appear again
      for (auto& kv : last_frame) kv.second = -1000;
    }
    std::vector<Box> dets;
    for (const Live& l : live)
      if (u(rng) < 0.85) dets.push_back(detect(l.a.at(t - l.born + 1.0), Eigen::Isometry3d::Identity(), true));
    const std::uint32_t max_before = max_seen;  // largest id of earlier frames
    for (const Box& b : tracker.update(dets, t, Eigen::Isometry3d::Identity())) {
      ASSERT_NE(b.track_id, 0u);
      auto it = last_frame.find(b.track_id);
      if (it == last_frame.end()) {
        EXPECT_GT(b.track_id, max_before) << "a new track reused an older id";
      } else {
        EXPECT_GT(f - it->second, 0) << "id " << b.track_id << " twice in one frame";
        EXPECT_LE(f - it->second, o.max_age + 1) << "id " << b.track_id << " came back after its track ended";
      }
      max_seen = std::max(max_seen, b.track_id);
      last_frame[b.track_id] = f;
    }
  }
  EXPECT_EQ(tracker.numResets(), 2u);
  EXPECT_GT(max_seen, 50u);
}

TEST(GreedyTracker, BirthScoreAndScoreThreshold) {
  TrackerOptions o;
  o.score_threshold = 0.2;
  o.birth_score = {0.5, 0.5, 0.5};
  GreedyTracker tracker(o);
  Box a = Actor{ObjectClass::Car, 10, 0, 10, 0}.at(0);
  a.score = 0.4f;  // too low to start a track
  EXPECT_TRUE(tracker.update({a}, 0.0, Eigen::Isometry3d::Identity()).empty());
  a = Actor{ObjectClass::Car, 10, 0, 10, 0}.at(0.1);
  a.score = 0.6f;
  const auto out = tracker.update({a}, 0.1, Eigen::Isometry3d::Identity());
  ASSERT_EQ(out.size(), 1u);
  const std::uint32_t id = out[0].track_id;
  a = Actor{ObjectClass::Car, 10, 0, 10, 0}.at(0.2);
  a.score = 0.3f;  // below birth, above the threshold: continues the track
  const auto cont = tracker.update({a}, 0.2, Eigen::Isometry3d::Identity());
  ASSERT_EQ(cont.size(), 1u);
  EXPECT_EQ(cont[0].track_id, id);
  a = Actor{ObjectClass::Car, 10, 0, 10, 0}.at(0.3);
  a.score = 0.1f;  // below the threshold: ignored
  EXPECT_TRUE(tracker.update({a}, 0.3, Eigen::Isometry3d::Identity()).empty());
}

// The pipeline's publishing options: fed from 0.05, born from 0.3, confirmed by a score of 0.5 or min_hits matches.
TrackerOptions publishingOptions(int min_hits) {
  TrackerOptions o;
  o.score_threshold = 0.05;
  o.birth_score = {0.3, 0.3, 0.3};
  o.confirm_score = {0.5, 0.5, 0.5};
  o.min_hits = {min_hits, min_hits, min_hits};
  return o;
}

// The publishing rule: a track's boxes are output from its confirming frame on (min_hits consecutive matches, or one
// detection scoring confirm_score); a false box seen in one frame alone is never output.
TEST(GreedyTracker, OnlyConfirmedTracksArePublished) {
  GreedyTracker tracker(publishingOptions(3));
  const Actor real{ObjectClass::Car, 10, 0, 10, 0};
  const Actor strong{ObjectClass::Pedestrian, 20, 5, 1, 0};
  std::vector<std::size_t> published_real;
  std::uint32_t real_id = 0;
  for (int f = 0; f < 10; ++f) {
    const double t = 0.1 * f;
    Box r = real.at(t);
    r.score = 0.35f;  // born and continued below confirm_score: confirmed by hits
    std::vector<Box> frame{r};
    // A one-frame false box every other frame, each at a new place, above birth but below confirm_score.
    if (f % 2 == 0) {
      Box clutter = Actor{ObjectClass::Pedestrian, -15.0 + 3 * f, -8, 0, 0}.at(t);
      clutter.score = 0.45f;
      frame.push_back(clutter);
    }
    if (f == 4) {  // confirmed at once by its score
      Box s = strong.at(t);
      s.score = 0.8f;
      frame.push_back(s);
    }
    const std::vector<Box> out = tracker.update(frame, t, Eigen::Isometry3d::Identity());
    for (const Box& b : out) {
      if (b.label == ObjectClass::Car) {
        published_real.push_back(static_cast<std::size_t>(f));
        if (real_id == 0) real_id = b.track_id;
        EXPECT_EQ(b.track_id, real_id) << "frame " << f;
      } else {
        EXPECT_EQ(f, 4) << "a one-frame false box was published in frame " << f;
        EXPECT_FLOAT_EQ(b.score, 0.8f);
      }
    }
  }
  // Frames 0 and 1 are tentative; from the third consecutive match on, every frame.
  EXPECT_EQ(published_real, (std::vector<std::size_t>{2, 3, 4, 5, 6, 7, 8, 9}));
}

// output_score: a confirmed track goes on through weak detections with its id, publishing only its frames that score
// output_score; another class without one publishes every matched frame.
TEST(GreedyTracker, AConfirmedTrackPublishesOnlyItsFramesAboveOutputScore) {
  TrackerOptions o = publishingOptions(1);
  o.output_score = {0.0, 0.3, 0.0};
  GreedyTracker tracker(o);
  const Actor ped{ObjectClass::Pedestrian, 10, 0, 1, 0};
  const Actor car{ObjectClass::Car, 20, 5, 10, 0};
  const std::vector<float> scores{0.8f, 0.2f, 0.25f, 0.6f, 0.1f};
  std::vector<std::size_t> ped_frames, car_frames;
  std::uint32_t ped_id = 0;
  for (std::size_t f = 0; f < scores.size(); ++f) {
    const double t = 0.1 * static_cast<double>(f);
    Box p = ped.at(t), c = car.at(t);
    p.score = c.score = scores[f];
    for (const Box& b : tracker.update({p, c}, t, Eigen::Isometry3d::Identity())) {
      if (b.label == ObjectClass::Car) {
        car_frames.push_back(f);
        continue;
      }
      ped_frames.push_back(f);
      if (ped_id == 0) ped_id = b.track_id;
      EXPECT_EQ(b.track_id, ped_id) << "the pedestrian's track went on through its weak frames, frame " << f;
    }
  }
  EXPECT_EQ(ped_frames, (std::vector<std::size_t>{0, 3}));
  EXPECT_EQ(car_frames, (std::vector<std::size_t>{0, 1, 2, 3, 4}));
  EXPECT_EQ(tracker.lastId(), 2u);  // one track each, never re-born
}

// A tentative track ends at its first miss: two hits, a gap, and it starts again from scratch (a new id).
TEST(GreedyTracker, ATentativeTrackEndsAtItsFirstMiss) {
  TrackerOptions o;
  o.birth_score = {0.3, 0.3, 0.3};
  o.confirm_score = {0.9, 0.9, 0.9};
  o.min_hits = {3, 3, 3};
  GreedyTracker tracker(o);
  const Actor a{ObjectClass::Car, 10, 0, 0, 0};
  std::size_t published = 0;
  for (int f = 0; f < 7; ++f) {
    Box b = a.at(0.1 * f);
    b.score = 0.5f;
    std::vector<Box> frame;
    if (f != 2) frame.push_back(b);  // missed in frame 2
    published += tracker.update(frame, 0.1 * f, Eigen::Isometry3d::Identity()).size();
  }
  EXPECT_EQ(published, 2u);  // frames 5 and 6: the third and fourth hits after the gap
  EXPECT_EQ(tracker.lastId(), 2u);
}

TEST(GreedyTracker, ClassesAreTrackedSeparatelyAndFieldsKept) {
  GreedyTracker tracker{TrackerOptions()};
  Box car = Actor{ObjectClass::Car, 10, 0, 0, 0}.at(0);
  Box ped = car;
  ped.label = ObjectClass::Pedestrian;  // same place, other class
  car.num_points = 77;
  car.score = 0.77f;
  Box unknown = car;
  unknown.label = ObjectClass::Unknown;
  Box bad = car;
  bad.x = std::nan("");
  LogCapture log;
  auto out = tracker.update({car, unknown, ped, bad}, 0.0, Eigen::Isometry3d::Identity());
  ASSERT_EQ(out.size(), 2u);
  EXPECT_EQ(out[0].label, ObjectClass::Car);
  EXPECT_EQ(out[0].num_points, 77u);
  EXPECT_FLOAT_EQ(out[0].score, 0.77f);
  EXPECT_EQ(out[1].label, ObjectClass::Pedestrian);
  EXPECT_NE(out[0].track_id, out[1].track_id);
  EXPECT_EQ(log.lines.size(), 2u);  // the Unknown class (once) and the non-finite box
  out = tracker.update({ped, car}, 0.1, Eigen::Isometry3d::Identity());
  ASSERT_EQ(out.size(), 2u);
  EXPECT_EQ(out[0].label, ObjectClass::Pedestrian);
  EXPECT_EQ(tracker.numTracks(), 2u);
}

TEST(GreedyTracker, HungarianMatchesMoreThanGreedyWhenGreedyBlocksItself) {
  // Two static cars 0.9 m apart, then detections that greedy (highest score first, nearest track) pairs so that the
  // second one falls outside every free gate: greedy starts a new track, Hungarian keeps both.
  auto car = [](double x, double y, float score) {
    Box b = Actor{ObjectClass::Car, x, y, 0, 0}.at(0);
    b.vx = b.vy = 0;
    b.score = score;
    return b;
  };
  for (AssignmentMethod m : {AssignmentMethod::Greedy, AssignmentMethod::Hungarian}) {
    TrackerOptions o = optionsFor(m);
    o.max_speed.car = 0.0;  // keep the gate at exactly 1 m for the new tracks of frame 0
    GreedyTracker tracker(o);
    const auto first = tracker.update({car(10, 0, 0.9f), car(10.9, 0, 0.8f)}, 0.0, Eigen::Isometry3d::Identity());
    ASSERT_EQ(first.size(), 2u);
    // Detection A (score 0.95) at 10.5 is nearer track 2 (0.4) than track 1 (0.5); B at 11.45 reaches only track 2
    // (0.55; track 1 is 1.45 away).
    const auto second = tracker.update({car(10.5, 0, 0.95f), car(11.45, 0, 0.85f)}, 0.1, Eigen::Isometry3d::Identity());
    ASSERT_EQ(second.size(), 2u);
    if (m == AssignmentMethod::Greedy) {
      EXPECT_EQ(second[0].track_id, first[1].track_id);
      EXPECT_GT(second[1].track_id, first[1].track_id);  // new track
    } else {
      EXPECT_EQ(second[0].track_id, first[0].track_id);  // A -> 1 (0.5) and B -> 2 (0.55): both matched
      EXPECT_EQ(second[1].track_id, first[1].track_id);
    }
  }
}

}  // namespace
}  // namespace ret3d
