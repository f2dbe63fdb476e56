// Reading Object3DArray messages back from bags, and `ret3d eval` run end to end on bags (the built command line).
#include "ret3d/ros/bag_objects.h"

#include <gtest/gtest.h>
#include <rosbag/bag.h>

#include <cstdio>
#include <fstream>
#include <sstream>

#include "ret3d/Object3DArray.h"
#include "ret3d/ros/conversions.h"
#include "support/boxes.h"
#include "support/error_message.h"
#include "support/test_util.h"

namespace ret3d {
namespace {

Box car(double x, std::uint32_t id, float score) {
  Box b = test::makeBox(x, 0.5, -1.0, 4.0, 1.7, 1.5, 0.1);  // a car on the road below a LiDAR mounted 1.73 m high
  b.label = ObjectClass::Car;
  b.track_id = id;
  b.score = score;
  b.num_points = 120;
  return b;
}

// `frames` messages stamped 1e9 + f / 10, one car 10..16 m ahead per frame.
void writeBag(const std::string& path, const std::string& topic, int frames, std::uint32_t id, float score) {
  rosbag::Bag bag(path, rosbag::bagmode::Write);
  for (int f = 0; f < frames; ++f) {
    std_msgs::Header h;
    h.stamp = ros::Time(1.0e9 + f / 10.0);
    h.frame_id = "velodyne";
    bag.write(topic, h.stamp, toMsg(std::vector<Box>{car(10.0 + 0.1 * f, id, score)}, h));
  }
  bag.close();
}

std::string run(const std::string& command) {
  std::string out;
  FILE* pipe = popen((command + " 2>&1").c_str(), "r");
  if (!pipe) return out;
  char buf[4096];
  while (std::fgets(buf, sizeof buf, pipe)) out += buf;
  pclose(pipe);
  return out;
}

std::string readAll(const std::string& path) {
  std::ifstream in(path);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

TEST(BagObjects, ReadsBackWhatWasWritten) {
  test::TempDir dir;
  writeBag(dir / "gt.bag", "/ground_truth/objects", 3, 5, 1.0f);
  const auto msgs = readBagObjects(dir / "gt.bag", "/ground_truth/objects");
  ASSERT_EQ(msgs.size(), 3u);
  EXPECT_NEAR(msgs[2].stamp, 1.0e9 + 0.2, 1e-6);
  EXPECT_EQ(msgs[0].frame_id, "velodyne");
  ASSERT_EQ(msgs[1].boxes.size(), 1u);
  EXPECT_NEAR(msgs[1].boxes[0].x, 10.1, 1e-6);
  EXPECT_EQ(msgs[1].boxes[0].track_id, 5u);
  EXPECT_EQ(msgs[1].boxes[0].label, ObjectClass::Car);
  EXPECT_EQ(msgs[1].boxes[0].num_points, 120u);
}

TEST(BagObjects, MissingTopicListsTheBagsTopics) {
  test::TempDir dir;
  writeBag(dir / "gt.bag", "/ground_truth/objects", 1, 5, 1.0f);
  const std::string msg = test::errorMessage([&] { readBagObjects(dir / "gt.bag", "/objects"); });
  EXPECT_NE(msg.find("/ground_truth/objects (ret3d/Object3DArray)"), std::string::npos) << msg;
  EXPECT_THROW(readBagObjects(dir / "missing.bag", "/objects"), std::runtime_error);
}

// Perfect predictions in a bag against bag ground truth: every metric family at 100 (60 frames, so the KITTI
// devkit's 41 recall samples are all reached).
TEST(EvalCommand, BagAgainstBagGivesFullMarksForPerfectPredictions) {
  test::TempDir dir;
  writeBag(dir / "gt.bag", "/ground_truth/objects", 60, 3, 1.0f);
  writeBag(dir / "pred.bag", "/objects", 60, 42, 0.9f);
  const std::string out = run(std::string(RET3D_CLI) + " eval --gt " + (dir / "gt.bag") + " --pred " +
                              (dir / "pred.bag") + " --out " + (dir / "report") + " --classes Car");
  const std::string json = readAll(dir / "report/metrics.json");
  ASSERT_FALSE(json.empty()) << out;
  for (const char* key : {"\"kitti.Car.3d.R40.easy\": 100", "\"kitti.Car.bev.R11.moderate\": 100",
                          "\"waymo.Car.L1.APH\": 100", "\"waymo.mean.L2.AP\": 100", "\"mot.Car.MOTA\": 100",
                          "\"mot.Car.HOTA\": 100", "\"mot.Car.IDSW\": 0", "\"count.frames\": 60"}) {
    EXPECT_NE(json.find(key), std::string::npos) << key << "\n" << json << "\n" << out;
  }
  EXPECT_NE(out.find("KITTI AP"), std::string::npos) << out;
  const std::string md = readAll(dir / "report/report.md");
  EXPECT_NE(md.find("converted to KITTI camera labels"), std::string::npos);
}

TEST(EvalCommand, NoMatchingTopicIsAClearError) {
  test::TempDir dir;
  writeBag(dir / "gt.bag", "/ground_truth/objects", 2, 3, 1.0f);
  const std::string out = run(std::string(RET3D_CLI) + " eval --gt " + (dir / "gt.bag") + " --pred " +
                              (dir / "gt.bag") + " --out " + (dir / "report"));
  EXPECT_NE(out.find("no topic /objects"), std::string::npos) << out;
}

}  // namespace
}  // namespace ret3d
