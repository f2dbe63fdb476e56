// rostest (test/rostest/bag_play_test.test): a bag made by `ret3d convert` replays through a live ROS graph. The node
// writes a tiny tracking sequence, converts it to a bag in a temporary folder, subscribes to /points,
// /ground_truth/objects and tf, then runs the real `rosbag play` as a child process and checks that every cloud and
// every ground-truth array arrives intact, and that tf places every cloud in odom at its stamp.
#include <gtest/gtest.h>
#include <ros/ros.h>
#include <tf2_ros/buffer.h>
#include <tf2_ros/transform_listener.h>
#include <unistd.h>

#include <mutex>

#include "ret3d/ros/conversions.h"
#include "ret3d/ros/kitti_bag.h"
#include "support/ros_test_util.h"
#include "support/test_util.h"
#include "support/tiny_sequence.h"

namespace ret3d {
namespace {

constexpr int kFrames = 5;

TEST(BagPlay, EveryCloudAndGroundTruthArrivesIntact) {
  test::TempDir tmp;
  test::TinySequence seq;
  seq.write(tmp.path(), "0000", kFrames, /*with_labels=*/true);
  const std::string bag = tmp / "play.bag";
  ASSERT_EQ(convertKittiToBag(tmp.path(), bag), static_cast<std::size_t>(kFrames));

  std::mutex mutex;
  std::vector<sensor_msgs::PointCloud2::ConstPtr> clouds;
  std::vector<ret3d::Object3DArray::ConstPtr> objects;
  ros::NodeHandle nh;
  const ros::Subscriber points_sub =
      nh.subscribe<sensor_msgs::PointCloud2>("/points", 100, [&](const sensor_msgs::PointCloud2::ConstPtr& m) {
        std::lock_guard<std::mutex> lock(mutex);
        clouds.push_back(m);
      });
  const ros::Subscriber objects_sub =
      nh.subscribe<ret3d::Object3DArray>("/ground_truth/objects", 100, [&](const ret3d::Object3DArray::ConstPtr& m) {
        std::lock_guard<std::mutex> lock(mutex);
        objects.push_back(m);
      });
  tf2_ros::Buffer tf_buffer;
  const tf2_ros::TransformListener tf_listener(tf_buffer, nh);
  ros::AsyncSpinner spinner(2);
  spinner.start();

  // --wait-for-subscribers: nothing is published before this node is connected to every topic.
  const std::string rosbag = access("/usr/bin/rosbag", X_OK) == 0 ? "/usr/bin/rosbag" : "rosbag";
  const std::string log = tmp / "rosbag_play.log";
  ASSERT_EQ(test::runLogged({rosbag, "play", "--quiet", "--wait-for-subscribers", bag}, log, 20.0), 0)
      << "rosbag play failed or timed out\n"
      << test::readText(log);
  // The last messages may still be in flight when rosbag exits.
  const auto all_arrived = [&] {
    std::lock_guard<std::mutex> lock(mutex);
    return clouds.size() >= static_cast<std::size_t>(kFrames) && objects.size() >= static_cast<std::size_t>(kFrames);
  };
  test::waitFor(all_arrived, 2.0);
  spinner.stop();

  std::lock_guard<std::mutex> lock(mutex);
  ASSERT_EQ(clouds.size(), static_cast<std::size_t>(kFrames));
  ASSERT_EQ(objects.size(), static_cast<std::size_t>(kFrames));
  const ros::Time start(ConvertOptions().start_time);
  for (int f = 0; f < kFrames; ++f) {
    const sensor_msgs::PointCloud2& msg = *clouds[f];
    const ros::Time stamp = start + ros::Duration(f / ConvertOptions().rate);
    EXPECT_EQ(msg.header.frame_id, "velodyne");
    EXPECT_NEAR(msg.header.stamp.toSec(), stamp.toSec(), 1e-6);
    // The velodyne driver layout, unchanged by the trip through the bag and the wire.
    ASSERT_EQ(msg.fields.size(), 6u);
    const char* names[6] = {"x", "y", "z", "intensity", "ring", "time"};
    for (int k = 0; k < 6; ++k) EXPECT_EQ(msg.fields[k].name, names[k]);
    EXPECT_EQ(msg.point_step, 22u);
    const PointCloud cloud = toCloud(msg);
    const PointCloud& want = seq.scans[f];
    ASSERT_EQ(cloud.size(), want.size());
    for (std::size_t i = 0; i < cloud.size(); ++i) {
      ASSERT_EQ(cloud.points[i].x, want.points[i].x) << "frame " << f << " point " << i;
      ASSERT_EQ(cloud.points[i].y, want.points[i].y);
      ASSERT_EQ(cloud.points[i].z, want.points[i].z);
      ASSERT_NEAR(cloud.points[i].intensity, want.points[i].intensity, 1e-6);
    }
    // tf from the replayed /tf and the latched /tf_static places the cloud in odom at its stamp.
    std::string error;
    EXPECT_TRUE(tf_buffer.canTransform("odom", "velodyne", msg.header.stamp, ros::Duration(0), &error))
        << "frame " << f << ": " << error;

    const ret3d::Object3DArray& gt = *objects[f];
    EXPECT_EQ(gt.header.stamp, msg.header.stamp);
    EXPECT_EQ(gt.header.frame_id, "velodyne");
    const std::vector<Box> boxes = fromMsg(gt);
    ASSERT_EQ(boxes.size(), 2u);
    EXPECT_EQ(boxes[0].label, ObjectClass::Car);
    EXPECT_EQ(boxes[1].label, ObjectClass::Pedestrian);
    EXPECT_EQ(boxes[0].num_points, static_cast<std::uint32_t>(test::TinySequence::kCarPoints));
    EXPECT_EQ(boxes[1].num_points, static_cast<std::uint32_t>(test::TinySequence::kPedestrianPoints));
    EXPECT_NEAR(boxes[0].x, seq.boxes[f][0].x, 1e-3);
  }
  // The static sensor mount arrived (latched) too.
  std::string error;
  EXPECT_TRUE(tf_buffer.canTransform("base_link", "velodyne", ros::Time(0), ros::Duration(0), &error)) << error;
}

}  // namespace
}  // namespace ret3d
