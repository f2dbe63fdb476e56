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

namespace ret3d {
namespace {

constexpr double kDt = 0.1;  // 10 Hz

// An object moving at constant velocity in the fixed frame.
struct Actor {
  ObjectClass label = ObjectClass::Car;
  double x0 = 0, y0 = 0, vx = 0, vy = 0;
  Box at(double t) const {
    Box b;
    b.x = x0 + vx * t;
    b.y = y0 + vy * t;
    b.z = 0.8;
    b.label = label;
    b.length = label == ObjectClass::Car ? 4.2 : label == ObjectClass::Cyclist ? 1.8 : 0.8;
    b.width = label == ObjectClass::Car ? 1.8 : 0.6;
    b.height = label == ObjectClass::Car ? 1.5 : 1.7;
    b.yaw = (vx != 0 || vy != 0) ? std::atan2(vy, vx) : 0.3;
    b.vx = vx;
    b.vy = vy;
    b.score = 0.9f;
    return b;
  }
};

// The sensor-frame detection of a fixed-frame box: what a detector with a velocity head reports (velocity over
// ground, rotated into the sensor frame), or, with_velocity = false, what one without reports (zero velocity).
Box detect(const Box& fixed, const Eigen::Isometry3d& sensor_to_fixed, bool with_velocity, double noise = 0.0,
           std::mt19937* rng = nullptr) {
  Box b = transformBox(fixed, sensor_to_fixed.inverse());
  if (!with_velocity) b.vx = b.vy = 0.0;
  if (rng && noise > 0) {
    std::normal_distribution<double> n(0.0, noise);
    b.x += n(*rng);
    b.y += n(*rng);
  }
  return b;
}

// Runs `frames` frames of actors through a tracker (ego static at the origin unless `ego` is given) and returns, per
// actor, the ids it was output with (0 for a frame where it was not output).
std::vector<std::vector<std::uint32_t>> run(GreedyTracker& tracker, const std::vector<Actor>& actors, int frames,
                                            bool with_velocity, double noise = 0.0,
                                            std::function<Eigen::Isometry3d(double)> ego = nullptr,
                                            double t0 = 0.0) {
  std::mt19937 rng(3);
  std::vector<std::vector<std::uint32_t>> ids(actors.size());
  for (int f = 0; f < frames; ++f) {
    const double t = t0 + f * kDt;
    const Eigen::Isometry3d pose = ego ? ego(t) : Eigen::Isometry3d::Identity();
    std::vector<Box> dets;
    for (const Actor& a : actors) dets.push_back(detect(a.at(t), pose, with_velocity, noise, &rng));
    const std::vector<Box> out = tracker.update(dets, t, pose);
    EXPECT_EQ(out.size(), dets.size()) << "frame " << f;
    for (std::size_t i = 0; i < actors.size(); ++i) {
      // Outputs keep the detections' order; find each actor's box by its position (unique within a frame).
      std::uint32_t id = 0;
      for (const Box& o : out)
        if (std::abs(o.x - dets[i].x) < 1e-9 && std::abs(o.y - dets[i].y) < 1e-9) id = o.track_id;
      ids[i].push_back(id);
    }
  }
  return ids;
}

// Each actor's ids: all equal and non-zero; different actors have different ids.
void expectOneIdPerActor(const std::vector<std::vector<std::uint32_t>>& ids, const std::string& what) {
  std::set<std::uint32_t> distinct;
  for (std::size_t a = 0; a < ids.size(); ++a) {
    ASSERT_FALSE(ids[a].empty());
    for (std::size_t f = 0; f < ids[a].size(); ++f) {
      EXPECT_NE(ids[a][f], 0u) << what << ": actor " << a << " not output at frame " << f;
      EXPECT_EQ(ids[a][f], ids[a][0]) << what << ": actor " << a << " changed id at frame " << f;
    }
    distinct.insert(ids[a][0]);
  }
  EXPECT_EQ(distinct.size(), ids.size()) << what << ": two actors share an id";
}

TrackerOptions optionsFor(AssignmentMethod m, bool use_velocity = true) {
  TrackerOptions o;
  o.assignment = m;
  o.use_detection_velocity = use_velocity;
  return o;
}

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

// Captures log lines while alive.
class LogCapture {
 public:
  LogCapture() {
    setLogSink([this](LogLevel, const std::string& m) { lines.push_back(m); });
  }
  ~LogCapture() { setLogSink(nullptr); }
  std::vector<std::string> lines;
};

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

// The publishing rule: a track's boxes are output from its confirming frame on (min_hits consecutive matches, or one
// detection scoring confirm_score); a false box seen in one frame alone is never output.
TEST(GreedyTracker, OnlyConfirmedTracksArePublished) {
  TrackerOptions o;
  o.score_threshold = 0.05;
  o.birth_score = {0.3, 0.3, 0.3};
  o.confirm_score = {0.5, 0.5, 0.5};
  o.min_hits = {3, 3, 3};
  GreedyTracker tracker(o);
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
