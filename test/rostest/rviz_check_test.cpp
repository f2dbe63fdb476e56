// rostest (test/rostest/rviz_check_test.test): rviz with rviz/ret3d.rviz under Xvfb shows the pipeline's markers in the
// class colours of include/ret3d/ros/markers.h. The node runs the real MarkerNodelet (in-process nodelet::Loader),
// feeds it a Car, a Pedestrian and a Cyclist beside a cloud with tf, starts Xvfb and rviz as child processes, takes a
// screenshot with imagemagick's `import` and finds each class colour in it. With RET3D_SCREENSHOT set, the screenshot
// is also copied there (docs/ret3d_rviz.png was made so).
#include <gtest/gtest.h>
#include <ros/ros.h>
#include <tf2_ros/static_transform_broadcaster.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <thread>

#include "ret3d/Object3DArray.h"
#include "ret3d/ros/conversions.h"
#include "ret3d/ros/markers.h"
#include "support/ros_test_util.h"
#include "support/test_util.h"
#include "support/tiny_sequence.h"

namespace ret3d {
namespace {

TEST(RvizCheck, ClassColoursOnScreen) {
  const char* package = std::getenv("RET3D_PACKAGE_DIR");
  ASSERT_NE(package, nullptr) << "RET3D_PACKAGE_DIR not set (test/rostest/rviz_check_test.test sets it)";
  test::TempDir tmp;
  const std::string log = tmp / "children.log";
  const std::string display = ":" + std::to_string(90 + getpid() % 9);
  const pid_t xvfb = test::spawnLogged({"Xvfb", display, "-screen", "0", "1280x720x24", "-nolisten", "tcp"}, log);
  ASSERT_GT(xvfb, 0);
  setenv("DISPLAY", display.c_str(), 1);
  setenv("LIBGL_ALWAYS_SOFTWARE", "1", 1);

  ros::NodeHandle nh;
  ros::AsyncSpinner spinner(2);
  spinner.start();
  nodelet::Loader loader(false);
  ASSERT_TRUE(test::loadNodelet(loader, "/ret3d_markers", "ret3d/MarkerNodelet"));
  tf2_ros::StaticTransformBroadcaster tf;
  geometry_msgs::TransformStamped odom_base, base_velo;
  odom_base.header.frame_id = "odom";
  odom_base.child_frame_id = "base_link";
  odom_base.transform.rotation.w = 1;
  base_velo.header.frame_id = "base_link";
  base_velo.child_frame_id = "velodyne";
  base_velo.transform.translation.z = 1.73;
  base_velo.transform.rotation.w = 1;
  tf.sendTransform({odom_base, base_velo});
  ros::Publisher objects = nh.advertise<ret3d::Object3DArray>("/objects", 1);
  ros::Publisher points = nh.advertise<sensor_msgs::PointCloud2>("/points", 1);

  // Large boxes near the focal point of the view, so each colour covers many pixels.
  std::vector<Box> boxes(3);
  boxes[0] = Box{12.0, 4.0, -0.9, 4.5, 2.0, 1.6, 0.3};
  boxes[0].label = ObjectClass::Car;
  boxes[1] = Box{8.0, -4.0, -0.8, 1.0, 1.0, 1.8, 0.0};
  boxes[1].label = ObjectClass::Pedestrian;
  boxes[2] = Box{16.0, -3.0, -0.8, 2.0, 1.0, 1.8, 1.2};
  boxes[2].label = ObjectClass::Cyclist;
  for (std::size_t i = 0; i < boxes.size(); ++i) {
    boxes[i].track_id = static_cast<std::uint32_t>(i + 1);
    boxes[i].score = 0.9f;
    boxes[i].vx = 3.0;
  }
  PointCloud cloud;
  for (const Box& b : boxes) test::addLatticeInside(b, 6, 0.8f, cloud);
  for (double x = 2; x < 30; x += 0.4) {
    for (double y = -12; y < 12; y += 0.4) cloud.points.push_back({float(x), float(y), -1.73f, 0.3f});
  }

  const std::string rviz_config = std::string(package) + "/rviz/ret3d.rviz";
  const pid_t rviz = test::spawnLogged({"rviz", "-d", rviz_config}, log);
  ASSERT_GT(rviz, 0);
  // Publish at 5 Hz while rviz comes up and renders (software GL is slow), then take the screenshot.
  const std::string shot = tmp / "shot.png";
  for (int i = 0; i < 100; ++i) {
    std_msgs::Header h;
    h.stamp = ros::Time::now();
    h.frame_id = "velodyne";
    objects.publish(toMsg(boxes, h));
    points.publish(toPointCloud2(cloud, h));
    std::this_thread::sleep_for(std::chrono::milliseconds(200));
  }
  const int import_rc = test::runLogged({"import", "-display", display, "-window", "root", shot}, log, 30.0);
  kill(rviz, SIGTERM);
  test::waitLogged(rviz, 10.0);
  kill(xvfb, SIGTERM);
  test::waitLogged(xvfb, 10.0);
  std::ifstream children(log);
  const std::string children_log((std::istreambuf_iterator<char>(children)), std::istreambuf_iterator<char>());
  ASSERT_EQ(import_rc, 0) << children_log;
  if (const char* keep = std::getenv("RET3D_SCREENSHOT")) std::filesystem::copy_file(shot, keep,
                                                             std::filesystem::copy_options::overwrite_existing);

  // Raw RGB pixels of the screenshot.
  const std::string raw = tmp / "shot.rgb";
  ASSERT_EQ(test::runLogged({"convert", shot, "-depth", "8", "rgb:" + raw}, log, 30.0), 0);
  std::ifstream in(raw, std::ios::binary);
  const std::string px((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  ASSERT_EQ(px.size(), 1280u * 720u * 3u);
  for (ObjectClass c : kDetectedClasses) {
    const auto want = classColour(c);
    std::size_t hits = 0;
    for (std::size_t i = 0; i + 2 < px.size(); i += 3) {
      bool near = true;
      for (int k = 0; k < 3; ++k) {
        near = near && std::abs(static_cast<int>(static_cast<unsigned char>(px[i + k])) -
                                static_cast<int>(want[k] * 255.0f)) <= 40;
      }
      hits += near ? 1 : 0;
    }
    EXPECT_GE(hits, 50u) << className(c) << " colour found on " << hits << " pixels\n" << children_log;
  }
}

}  // namespace
}  // namespace ret3d
