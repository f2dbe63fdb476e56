// Box <-> Object3D messages (ros/conversions.h): round trips of pose, size, velocity, score, class and track id.
#include "ret3d/ros/conversions.h"

#include <gtest/gtest.h>

#include <cmath>

#include "support/boxes.h"

namespace ret3d {
namespace {

Box makeBox(double yaw) {
  Box b = test::makeBox(12.5, -3.25, -0.8, 4.2, 1.8, 1.55, yaw);
  b.vx = 3.5;
  b.vy = -0.5;
  b.score = 0.875f;
  b.label = ObjectClass::Cyclist;
  b.track_id = 42;
  b.num_points = 317;
  return b;
}

TEST(BoxMsg, RoundTripAcrossYawsIncludingPi) {
  for (double yaw : {0.0, 0.3, -0.3, M_PI / 2, -M_PI / 2, 3.0, -3.0, M_PI, M_PI - 1e-9, -M_PI + 1e-9}) {
    const Box in = makeBox(yaw);
    const ret3d::Object3D msg = toMsg(in);
    EXPECT_NEAR(msg.pose.orientation.x * msg.pose.orientation.x + msg.pose.orientation.y * msg.pose.orientation.y +
                    msg.pose.orientation.z * msg.pose.orientation.z + msg.pose.orientation.w * msg.pose.orientation.w,
                1.0, 1e-12);
    EXPECT_EQ(msg.label, ret3d::Object3D::CYCLIST);
    EXPECT_DOUBLE_EQ(msg.dimensions.x, 4.2);
    EXPECT_DOUBLE_EQ(msg.dimensions.y, 1.8);
    EXPECT_DOUBLE_EQ(msg.dimensions.z, 1.55);
    const Box out = fromMsg(msg);
    // Same heading; a yaw of pi stays pi (the half-open interval (-pi, pi]).
    EXPECT_NEAR(std::remainder(out.yaw - yaw, 2 * M_PI), 0.0, 1e-9) << yaw;
    EXPECT_GT(out.yaw, -M_PI);
    EXPECT_LE(out.yaw, M_PI);
    test::expectSameCentreAndSize(out, in, 0.0);  // float64 fields both ways: exact
    EXPECT_DOUBLE_EQ(out.vx, in.vx);
    EXPECT_DOUBLE_EQ(out.vy, in.vy);
    EXPECT_EQ(out.score, in.score);
    EXPECT_EQ(out.label, in.label);
    EXPECT_EQ(out.track_id, in.track_id);
    EXPECT_EQ(out.num_points, in.num_points);
  }
  EXPECT_NEAR(fromMsg(toMsg(makeBox(M_PI))).yaw, M_PI, 1e-12);
  EXPECT_NEAR(fromMsg(toMsg(makeBox(-M_PI))).yaw, M_PI, 1e-12);
}

TEST(BoxMsg, QuaternionIsARotationAboutZ) {
  const ret3d::Object3D msg = toMsg(makeBox(M_PI / 2));
  EXPECT_NEAR(msg.pose.orientation.w, std::sqrt(0.5), 1e-12);
  EXPECT_NEAR(msg.pose.orientation.z, std::sqrt(0.5), 1e-12);
  EXPECT_EQ(msg.pose.orientation.x, 0.0);
  EXPECT_EQ(msg.pose.orientation.y, 0.0);
  // The quaternion -q is the same rotation.
  ret3d::Object3D neg = msg;
  neg.pose.orientation.w = -neg.pose.orientation.w;
  neg.pose.orientation.z = -neg.pose.orientation.z;
  EXPECT_NEAR(fromMsg(neg).yaw, M_PI / 2, 1e-12);
}

TEST(BoxMsg, UnknownLabelValueBecomesUnknown) {
  ret3d::Object3D msg = toMsg(makeBox(0));
  msg.label = 17;
  EXPECT_EQ(fromMsg(msg).label, ObjectClass::Unknown);
}

TEST(BoxMsg, ArrayRoundTripKeepsHeaderAndOrder) {
  std::vector<Box> boxes;
  for (int i = 0; i < 5; ++i) {
    Box b = makeBox(0.5 * i - 1.0);
    b.track_id = static_cast<std::uint32_t>(i + 1);
    b.label = kDetectedClasses[i % 3];
    boxes.push_back(b);
  }
  std_msgs::Header header;
  header.frame_id = "velodyne";
  header.stamp.fromSec(99.25);
  const ret3d::Object3DArray msg = toMsg(boxes, header);
  EXPECT_EQ(msg.header.frame_id, "velodyne");
  EXPECT_EQ(msg.header.stamp, header.stamp);
  const std::vector<Box> back = fromMsg(msg);
  ASSERT_EQ(back.size(), boxes.size());
  for (std::size_t i = 0; i < boxes.size(); ++i) {
    EXPECT_EQ(back[i].track_id, boxes[i].track_id);
    EXPECT_EQ(back[i].label, boxes[i].label);
    EXPECT_NEAR(back[i].yaw, boxes[i].yaw, 1e-12);
  }
  EXPECT_TRUE(fromMsg(toMsg(std::vector<Box>{}, header)).empty());
}

}  // namespace
}  // namespace ret3d
