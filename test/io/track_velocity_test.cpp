#include "ret3d/io/track_velocity.h"

#include <cmath>

#include <gtest/gtest.h>

namespace ret3d {
namespace {

Box at(double x, double y, std::uint32_t id) {
  Box b;
  b.x = x, b.y = y, b.length = 4, b.width = 2, b.height = 1.5, b.label = ObjectClass::Car, b.track_id = id;
  return b;
}

TEST(TrackVelocity, FromThePreviousFrameElseTheNext) {
  // Track 1 moves +1 m per frame along x (10 m/s at 10 Hz); track 2 appears in frame 1 only; track 3 in 0 and 1.
  std::vector<std::vector<Box>> frames = {{at(0, 0, 1), at(5, 5, 3)}, {at(1, 0, 1), at(9, 9, 2), at(5, 5.5, 3)}};
  const auto valid = setTrackVelocities(&frames, {}, 0.1);
  EXPECT_TRUE(valid[0][0]);  // from the next frame
  EXPECT_NEAR(frames[0][0].vx, 10, 1e-9);
  EXPECT_NEAR(frames[1][0].vx, 10, 1e-9);
  EXPECT_NEAR(frames[1][0].vy, 0, 1e-9);
  EXPECT_FALSE(valid[1][1]);  // a lone box
  EXPECT_EQ(frames[1][1].vx, 0);
  EXPECT_NEAR(frames[1][2].vy, 5, 1e-9);
}

TEST(TrackVelocity, EgoMotionIsRemoved) {
  // A parked car seen from a sensor driving +1.5 m per frame along x: in the sensor frame it approaches by 1.5 m,
  // but over ground it does not move.
  std::vector<std::vector<Box>> frames = {{at(20, 3, 4)}, {at(18.5, 3, 4)}};
  Eigen::Isometry3d p0 = Eigen::Isometry3d::Identity(), p1 = Eigen::Isometry3d::Identity();
  p1.translation() = Eigen::Vector3d(1.5, 0, 0);
  const auto valid = setTrackVelocities(&frames, {p0, p1}, 0.1);
  ASSERT_TRUE(valid[1][0]);
  EXPECT_NEAR(frames[1][0].vx, 0, 1e-9);
  EXPECT_NEAR(frames[0][0].vx, 0, 1e-9);
}

}  // namespace
}  // namespace ret3d
