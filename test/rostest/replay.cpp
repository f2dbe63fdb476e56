// rostest (test/rostest/replay.test, node `replay`): the bag-replay harness. The node writes a tiny sequence, converts
// it to a bag with the project's converter, saves real (untrained) model files with the stages' own save functions,
// then runs the real `roslaunch ret3d replay.launch bag:=... record:=...` (all five nodelets in one manager, rosbag
// play --clock with use_sim_time, rosbag record) as a child process and checks the recorded bag: an /objects message
// for every input cloud (drops at most 1 %), stamps and frame ids kept, the ground truth recorded beside it, and an
// /objects/detections message (upstream vision_msgs' type and md5) beside each /objects with as many detections. Accuracy
// (mAP, id stability against the ground truth) with the trained default models on a simulated drive:
// test/rostest/replay_accuracy.cpp.
#include <gtest/gtest.h>
#include <ros/ros.h>
#include <rosbag/bag.h>
#include <rosbag/view.h>
#include <vision_msgs/Detection3DArray.h>

#include <filesystem>
#include <fstream>
#include <map>
#include <set>
#include <sstream>

#include "ret3d/ros/bag_objects.h"
#include "ret3d/ros/kitti_bag.h"
#include "support/ros_test_util.h"
#include "support/test_util.h"
#include "support/tiny_models.h"
#include "support/tiny_sequence.h"
#include "support/vision_msgs_upstream.h"

namespace ret3d {
namespace {

constexpr int kFrames = 10;

using test::readText;

TEST(Replay, EveryCloudGivesObjectsInTheRecordedBag) {
  const char* package = std::getenv("RET3D_PACKAGE_DIR");
  ASSERT_NE(package, nullptr) << "RET3D_PACKAGE_DIR not set (test/rostest/replay.test sets it)";
  test::TempDir tmp;
  test::TinySequence seq;
  seq.write(tmp.path(), "0000", kFrames, /*with_labels=*/true);
  const std::string bag = tmp / "tiny.bag";
  ASSERT_EQ(convertKittiToBag(tmp.path(), bag), static_cast<std::size_t>(kFrames));

  // Model files: the detector on a small grid (quick on 2 cores), the relation modules at small widths.
  test::writeTinyModels(tmp.path(), package);

  const std::string out = tmp / "out.bag";
  const std::string log = tmp / "roslaunch.log";
  // rate 0.5: 5 clouds a second leave an untrained full-size pipeline on a busy 2-core CI machine room to keep up.
  const int rc = test::runLogged({"roslaunch", "--wait", "ret3d", "replay.launch", "bag:=" + bag, "record:=" + out,
                      "rviz:=false", "rate:=0.5", "delay:=6", "tail:=3", "threads:=1",
                      "detector_model:=" + (tmp / "detector.pt"), "detector_config:=" + (tmp / "detector.yaml"),
                      "intra_model:=" + (tmp / "intra_rm.pt"), "inter_model:=" + (tmp / "inter_rm.pt")},
                                 log, 75.0);
  const std::string launch_log = readText(log);
  ASSERT_EQ(rc, 0) << launch_log;
  ASSERT_TRUE(std::filesystem::exists(out)) << launch_log;

  const std::vector<StampedObjects> objects = readBagObjects(out, "/objects");
  const std::vector<StampedObjects> truth = readBagObjects(out, "/ground_truth/objects");
  EXPECT_EQ(truth.size(), static_cast<std::size_t>(kFrames)) << launch_log;
  std::set<double> out_stamps;
  for (const auto& o : objects) {
    EXPECT_EQ(o.frame_id, "velodyne");
    out_stamps.insert(o.stamp);
  }
  std::size_t missing = 0;
  for (const auto& t : truth) missing += out_stamps.count(t.stamp) == 0 ? 1 : 0;
  // Drops at most 1 %: with 10 frames, none.
  EXPECT_LE(missing * 100, truth.size()) << missing << " of " << truth.size() << " clouds without /objects\n"
                                         << launch_log;
  EXPECT_EQ(objects.size(), truth.size()) << launch_log;
  // Every output stamp is an input stamp.
  std::set<double> in_stamps;
  for (const auto& t : truth) in_stamps.insert(t.stamp);
  for (double s : out_stamps) EXPECT_EQ(in_stamps.count(s), 1u) << "output stamp " << s << " is no input's";

  // The same objects as vision_msgs/Detection3DArray, recorded with upstream's type and md5.
  std::map<double, std::size_t> objects_at;
  for (const auto& o : objects) objects_at[o.stamp] = o.boxes.size();
  rosbag::Bag recorded(out, rosbag::bagmode::Read);
  rosbag::View view(recorded, rosbag::TopicQuery("/objects/detections"));
  ASSERT_EQ(view.size(), objects.size()) << launch_log;
  for (const rosbag::ConnectionInfo* c : view.getConnections()) {
    EXPECT_EQ(c->datatype, "vision_msgs/Detection3DArray");
    EXPECT_EQ(c->md5sum, test::upstreamVisionMsgsMd5().front().second);
  }
  for (const rosbag::MessageInstance& m : view) {
    const vision_msgs::Detection3DArray::ConstPtr d = m.instantiate<vision_msgs::Detection3DArray>();
    ASSERT_NE(d, nullptr);
    EXPECT_EQ(d->header.frame_id, "velodyne");
    ASSERT_EQ(objects_at.count(d->header.stamp.toSec()), 1u) << "no /objects at " << d->header.stamp;
    EXPECT_EQ(d->detections.size(), objects_at[d->header.stamp.toSec()]);
  }
}

}  // namespace
}  // namespace ret3d
