#pragma once
// Scenes for the greedy tracker's tests (test/tracking/greedy_tracker*_test.cpp): objects at constant velocity in the
// fixed frame, their detections, a tracker run over them, and a log capture.

#include <gtest/gtest.h>

#include <cmath>
#include <functional>
#include <random>
#include <set>
#include <string>
#include <vector>

#include "ret3d/core/log.h"
#include "ret3d/core/transform.h"
#include "ret3d/tracking/greedy_tracker.h"

namespace ret3d {
namespace test {

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
inline Box detect(const Box& fixed, const Eigen::Isometry3d& sensor_to_fixed, bool with_velocity, double noise = 0.0,
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
inline std::vector<std::vector<std::uint32_t>> run(GreedyTracker& tracker, const std::vector<Actor>& actors, int frames,
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
inline void expectOneIdPerActor(const std::vector<std::vector<std::uint32_t>>& ids, const std::string& what) {
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

inline TrackerOptions optionsFor(AssignmentMethod m, bool use_velocity = true) {
  TrackerOptions o;
  o.assignment = m;
  o.use_detection_velocity = use_velocity;
  return o;
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

}  // namespace test
}  // namespace ret3d
