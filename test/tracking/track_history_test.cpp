#include "ret3d/tracking/track_history.h"

#include <gtest/gtest.h>

#include <cmath>

#include "ret3d/core/transform.h"
#include "support/boxes.h"

namespace ret3d {
namespace {

Box boxAt(double x, double y, double yaw = 0.0) {
  Box b = test::makeBox(x, y, 1.0, 4, 2, 1.5, yaw);
  b.label = ObjectClass::Car;
  return b;
}

TEST(TrackHistory, RingBufferKeepsNewestInOrder) {
  TrackHistory h(3);
  EXPECT_TRUE(h.empty());
  for (int i = 0; i < 5; ++i) h.push(boxAt(i, 0), 0.1 * i);
  ASSERT_EQ(h.size(), 3u);
  EXPECT_EQ(h.capacity(), 3u);
  EXPECT_DOUBLE_EQ(h[0].box.x, 2);
  EXPECT_DOUBLE_EQ(h[1].box.x, 3);
  EXPECT_DOUBLE_EQ(h[2].box.x, 4);
  EXPECT_DOUBLE_EQ(h.newest().stamp, 0.4);
  h.clear();
  EXPECT_EQ(h.size(), 0u);
  h.push(boxAt(9, 0), 1.0);
  EXPECT_DOUBLE_EQ(h[0].box.x, 9);
  EXPECT_THROW(TrackHistory(0), std::invalid_argument);
}

TEST(TrackHistory, OneEntryHistory) {
  TrackHistory h(1);
  h.push(boxAt(1, 2), 5.0);
  h.push(boxAt(3, 4), 5.1);
  const std::vector<TimedBox> s = h.inSensorFrame(5.1, Eigen::Isometry3d::Identity());
  ASSERT_EQ(s.size(), 1u);
  EXPECT_DOUBLE_EQ(s[0].box.x, 3);
  EXPECT_DOUBLE_EQ(s[0].dt, 0.0);
}

TEST(TrackHistory, MovedIntoSensorFrameByHand) {
  // Entries in the fixed frame; the sensor now stands at (10, 5, 0) facing +y (yaw 90 deg).
  TrackHistory h(10);
  Box a = boxAt(12, 5, 0.0);
  a.vx = 3;
  a.vy = 0;
  h.push(a, 100.0);
  h.push(boxAt(10, 9, M_PI / 2), 100.2);
  const Eigen::Isometry3d sensor_to_fixed = makeTransform(10, 5, 0, M_PI / 2);
  const std::vector<TimedBox> s = h.inSensorFrame(100.3, sensor_to_fixed);
  ASSERT_EQ(s.size(), 2u);
  // (12, 5) is 2 m along fixed +x from the sensor = 2 m to its right: sensor (0, -2); heading 0 becomes -90 deg.
  EXPECT_NEAR(s[0].box.x, 0.0, 1e-12);
  EXPECT_NEAR(s[0].box.y, -2.0, 1e-12);
  EXPECT_NEAR(s[0].box.z, 1.0, 1e-12);
  EXPECT_NEAR(s[0].box.yaw, -M_PI / 2, 1e-12);
  EXPECT_NEAR(s[0].box.vx, 0.0, 1e-12);  // fixed +x velocity is sensor -y
  EXPECT_NEAR(s[0].box.vy, -3.0, 1e-12);
  EXPECT_NEAR(s[0].dt, -0.3, 1e-9);
  // (10, 9) is 4 m ahead of the sensor: (4, 0), heading along the sensor's x.
  EXPECT_NEAR(s[1].box.x, 4.0, 1e-12);
  EXPECT_NEAR(s[1].box.y, 0.0, 1e-12);
  EXPECT_NEAR(s[1].box.yaw, 0.0, 1e-12);
  EXPECT_NEAR(s[1].dt, -0.1, 1e-9);
  EXPECT_DOUBLE_EQ(s[1].box.length, 4.0);  // sizes unchanged
}

TEST(TrackHistory, FeaturesTravelWithTheirBoxes) {
  TrackHistory h(2);
  EXPECT_EQ(h.feature(0), nullptr);
  for (int i = 0; i < 3; ++i) {
    const float f[3] = {float(i), float(10 * i), float(100 * i)};
    h.push(boxAt(i, 0), i, f, 3);
  }
  ASSERT_EQ(h.featureDim(), 3u);
  ASSERT_EQ(h.size(), 2u);
  for (std::size_t i = 0; i < 2; ++i) {
    EXPECT_FLOAT_EQ(h.feature(i)[0], h[i].box.x);
    EXPECT_FLOAT_EQ(h.feature(i)[2], 100 * h[i].box.x);
  }
  const float g[2] = {1, 2};
  EXPECT_THROW(h.push(boxAt(0, 0), 4, g, 2), std::invalid_argument);
  h.clear();
  h.push(boxAt(0, 0), 5, g, 2);  // a cleared history takes a new feature size
  EXPECT_EQ(h.featureDim(), 2u);
  EXPECT_FLOAT_EQ(h.feature(0)[1], 2.0f);
}

}  // namespace
}  // namespace ret3d
