// The main of every rostest node (test/rostest/<name>.cpp, linked in by CMakeLists.txt): gtest, then the ROS node
// RET3D_TEST_NODE (the test's name; the .test file's launch renames it anyway). The NodeHandle starts the node and
// keeps it up between the tests: without one, the last NodeHandle a test drops would shut it down.
#include <gtest/gtest.h>
#include <ros/ros.h>

int main(int argc, char** argv) {
  testing::InitGoogleTest(&argc, argv);
  ros::init(argc, argv, RET3D_TEST_NODE);
  ros::NodeHandle nh;
  return RUN_ALL_TESTS();
}
