#include "ret3d/ros/detection3d.h"

#include <gtest/gtest.h>
#include <ros/message_traits.h>

#include <cmath>

#include "ret3d/ros/conversions.h"
#include "support/boxes.h"
#include "support/vision_msgs_upstream.h"

namespace ret3d {
namespace {

template <typename M>
void expectUpstream(const std::string& type) {
  EXPECT_EQ(ros::message_traits::DataType<M>::value(), type);
  for (const auto& [name, md5] : test::upstreamVisionMsgsMd5())
    if (name == type) {
      EXPECT_EQ(ros::message_traits::MD5Sum<M>::value(), md5) << type << " differs from upstream vision_msgs 0.0.2";
      return;
    }
  ADD_FAILURE() << "no upstream md5 listed for " << type;
}

// The messages this package builds against are vision_msgs 0.0.2's: a node built against upstream's connects.
TEST(Detection3D, MessagesCarryUpstreamTypesAndMd5sums) {
  expectUpstream<vision_msgs::Detection3DArray>("vision_msgs/Detection3DArray");
  expectUpstream<vision_msgs::Detection3D>("vision_msgs/Detection3D");
  expectUpstream<vision_msgs::ObjectHypothesisWithPose>("vision_msgs/ObjectHypothesisWithPose");
  expectUpstream<vision_msgs::BoundingBox3D>("vision_msgs/BoundingBox3D");
}

double yawOfQuaternion(const geometry_msgs::Quaternion& q) {
  return std::atan2(2.0 * (q.w * q.z + q.x * q.y), 1.0 - 2.0 * (q.y * q.y + q.z * q.z));
}

TEST(Detection3D, OneDetectionPerObjectWithClassScoreAndBox) {
  Box car = test::carBox(12.5, -3.25);
  car.yaw = 2.5;
  car.score = 0.875f;
  car.track_id = 7;
  Box pedestrian = test::makeBox(-4.0, 6.0, -0.8, 0.8, 0.6, 1.75, -1.0);
  pedestrian.label = ObjectClass::Pedestrian;
  pedestrian.score = 0.5f;
  Box cyclist = test::makeBox(20.0, 1.0, -0.7, 1.8, 0.6, 1.7, 0.25);
  cyclist.label = ObjectClass::Cyclist;
  cyclist.score = 0.25f;
  std_msgs::Header header;
  header.stamp = ros::Time(1234, 500000000);
  header.frame_id = "velodyne";
  const std::vector<Box> boxes = {car, pedestrian, cyclist};

  const vision_msgs::Detection3DArray msg = toDetection3DArray(toMsg(boxes, header));
  EXPECT_EQ(msg.header.stamp, header.stamp);
  EXPECT_EQ(msg.header.frame_id, "velodyne");
  ASSERT_EQ(msg.detections.size(), 3u);
  const int ids[] = {1, 2, 3};  // the documented mapping: Object3D's label constants
  for (std::size_t i = 0; i < boxes.size(); ++i) {
    const vision_msgs::Detection3D& d = msg.detections[i];
    const Box& b = boxes[i];
    EXPECT_EQ(d.header.stamp, header.stamp);
    EXPECT_EQ(d.header.frame_id, "velodyne");
    ASSERT_EQ(d.results.size(), 1u);
    EXPECT_EQ(d.results[0].id, ids[i]);
    EXPECT_DOUBLE_EQ(d.results[0].score, b.score);
    EXPECT_DOUBLE_EQ(d.bbox.center.position.x, b.x);
    EXPECT_DOUBLE_EQ(d.bbox.center.position.y, b.y);
    EXPECT_DOUBLE_EQ(d.bbox.center.position.z, b.z);
    EXPECT_NEAR(yawOfQuaternion(d.bbox.center.orientation), b.yaw, 1e-12);
    EXPECT_DOUBLE_EQ(d.bbox.size.x, b.length);
    EXPECT_DOUBLE_EQ(d.bbox.size.y, b.width);
    EXPECT_DOUBLE_EQ(d.bbox.size.z, b.height);
    // The hypothesis' pose is the box centre too; no covariance is claimed; no points are copied.
    EXPECT_EQ(d.results[0].pose.pose, d.bbox.center);
    for (double c : d.results[0].pose.covariance) EXPECT_EQ(c, 0.0);
    EXPECT_TRUE(d.source_cloud.data.empty());
  }
}

TEST(Detection3D, EmptyFrameGivesAnEmptyArrayWithTheHeader) {
  ret3d::Object3DArray objects;
  objects.header.stamp = ros::Time(5, 0);
  objects.header.frame_id = "os_sensor";
  const vision_msgs::Detection3DArray msg = toDetection3DArray(objects);
  EXPECT_TRUE(msg.detections.empty());
  EXPECT_EQ(msg.header.frame_id, "os_sensor");
  EXPECT_EQ(msg.header.stamp, objects.header.stamp);
}

}  // namespace
}  // namespace ret3d
