// rostest (test/rostest/pipeline_chain_test.test): the IntraRM -> tracker -> InterRM -> marker nodelets, loaded in one
// real nodelet manager (in-process nodelet::Loader), fed the ground truth of a bag made by the project's converter from
// a tiny generated sequence (its /tf, /tf_static and /ground_truth/objects, the latter published as detections).
// Checks: an output on every topic for every input frame, stamps and frame ids kept, track ids stable, markers as
// documented (DELETEALL first, class colours, labels, arrows, trails); the pipeline keeps going and says so when the
// transform is missing or stamps go backwards; a nodelet with an invalid parameter or a missing/corrupt model file
// refuses to start with a message naming the parameter, its value and what is wrong. The objects also come out as
// vision_msgs/Detection3DArray (objects/detections) matching /objects frame by frame, with upstream vision_msgs'
// type and md5 as `rostopic type` and `rosmsg md5` see them; ~publish_detections false leaves the topic out.
#include <gtest/gtest.h>
#include <ros/ros.h>
#include <rosbag/bag.h>
#include <rosbag/view.h>
#include <tf2_msgs/TFMessage.h>
#include <vision_msgs/Detection3DArray.h>
#include <visualization_msgs/MarkerArray.h>

#include <cctype>
#include <filesystem>
#include <fstream>
#include <map>
#include <mutex>

#include "ret3d/DetectionArray.h"
#include "ret3d/Object3DArray.h"
#include "ret3d/relation/inter_rm.h"
#include "ret3d/relation/intra_rm.h"
#include "ret3d/ros/conversions.h"
#include "ret3d/ros/kitti_bag.h"
#include "support/boxes.h"
#include "support/ros_test_util.h"
#include "support/test_util.h"
#include "support/tiny_sequence.h"
#include "support/vision_msgs_upstream.h"

namespace ret3d {
namespace {

constexpr int kFrames = 8;

// One bag frame: its tf messages and its ground truth.
struct BagFrames {
  std::vector<tf2_msgs::TFMessage::ConstPtr> tf_static;
  std::vector<std::vector<tf2_msgs::TFMessage::ConstPtr>> tf;  // per frame, the /tf before its objects
  std::vector<ret3d::Object3DArray::ConstPtr> objects;
};

BagFrames readFrames(const std::string& path) {
  rosbag::Bag bag(path, rosbag::bagmode::Read);
  rosbag::View view(bag);
  BagFrames f;
  std::vector<tf2_msgs::TFMessage::ConstPtr> pending;
  for (const rosbag::MessageInstance& m : view) {
    if (m.getTopic() == "/tf_static") f.tf_static.push_back(m.instantiate<tf2_msgs::TFMessage>());
    if (m.getTopic() == "/tf") pending.push_back(m.instantiate<tf2_msgs::TFMessage>());
    if (m.getTopic() == "/ground_truth/objects") {
      f.objects.push_back(m.instantiate<ret3d::Object3DArray>());
      f.tf.push_back(pending);
      pending.clear();
    }
  }
  return f;
}

ret3d::DetectionArray::Ptr asDetections(const ret3d::Object3DArray& gt) {
  ret3d::DetectionArray::Ptr d(new ret3d::DetectionArray);
  d->header = gt.header;
  d->objects = gt.objects;
  for (auto& o : d->objects) {
    o.track_id = 0;  // the tracker's job
    o.score = 0.9f;
  }
  return d;
}

class PipelineChain : public ::testing::Test {
 protected:
  void SetUp() override {
    seq_.write(tmp_.path(), "0000", kFrames, /*with_labels=*/true);
    bag_ = tmp_ / "tiny.bag";
    ASSERT_EQ(convertKittiToBag(tmp_.path(), bag_), static_cast<std::size_t>(kFrames));
    frames_ = readFrames(bag_);
    ASSERT_EQ(frames_.objects.size(), static_cast<std::size_t>(kFrames));
    // Real model files, written by the stages' own save functions (untrained: refinement starts as the identity).
    relation::IntraRM(relation::IntraRMArch{}, 1).save(tmp_ / "intra_rm.pt");
    relation::InterRMArch inter_arch;
    inter_arch.c_enc = 64;
    inter_arch.heads = 4;
    relation::InterRM(inter_arch, 1).save(tmp_ / "inter_rm.pt");
    ros::param::set("/ret3d_intra/model_path", tmp_ / "intra_rm.pt");
    ros::param::set("/ret3d_intra/threads", 1);
    ros::param::set("/ret3d_inter/model_path", tmp_ / "inter_rm.pt");
    ros::param::set("/ret3d_inter/threads", 1);
    // An untrained IntraRM scores near its prior, so every refined box may start a track here. The tiny sequence's
    // pedestrian stands still in the sensor frame while the ego drives 10 m/s: over ground it "runs" at 10 m/s.
    XmlRpc::XmlRpcValue tracker;
    tracker["score_threshold"] = 0.0;
    tracker["birth_score"] = 0.0;
    tracker["max_speed"]["Car"] = 30.0;
    tracker["max_speed"]["Pedestrian"] = 15.0;
    tracker["max_speed"]["Cyclist"] = 10.0;
    ros::param::set("/ret3d_tracker/tracker", tracker);
  }
  void TearDown() override {
    for (const char* n : {"/ret3d_intra", "/ret3d_inter", "/ret3d_tracker", "/ret3d_markers"}) ros::param::del(n);
  }

  // Loads the four nodelets and subscribes to their outputs.
  void startPipeline(nodelet::Loader& loader) {
    ASSERT_TRUE(test::loadNodelet(loader, "/ret3d_intra", "ret3d/IntraRMNodelet")) << log_.all();
    ASSERT_TRUE(test::loadNodelet(loader, "/ret3d_tracker", "ret3d/TrackerNodelet")) << log_.all();
    ASSERT_TRUE(test::loadNodelet(loader, "/ret3d_inter", "ret3d/InterRMNodelet")) << log_.all();
    ASSERT_TRUE(test::loadNodelet(loader, "/ret3d_markers", "ret3d/MarkerNodelet")) << log_.all();
    intra_.listen(nh_, "/detections_intra");
    tracked_.listen(nh_, "/tracked");
    objects_.listen(nh_, "/objects");
    markers_.listen(nh_, "/objects/markers");
    detections_.listen(nh_, "/objects/detections");
    detections_pub_ = nh_.advertise<ret3d::DetectionArray>("/detections", 10);
    tf_pub_ = nh_.advertise<tf2_msgs::TFMessage>("/tf", 100);
    tf_static_pub_ = nh_.advertise<tf2_msgs::TFMessage>("/tf_static", 10, /*latch=*/true);
    ASSERT_TRUE(test::waitFor(
        [&] {
          // (Subscribers within one process share one subscription: one count for all the tf listeners.)
          return detections_pub_.getNumSubscribers() > 0 && tf_pub_.getNumSubscribers() > 0 &&
                 markers_.sub.getNumPublishers() > 0 && objects_.sub.getNumPublishers() > 0;
        },
        10.0));
    for (const auto& m : frames_.tf_static) tf_static_pub_.publish(m);
    // All of the sequence's tf up front (as a bag delivers tf with or before its clouds), so that no frame depends on
    // how fast the listeners connected; the missing-transform case is tested on its own below.
    ros::WallDuration(0.5).sleep();
    for (const auto& frame : frames_.tf) {
      for (const auto& m : frame) tf_pub_.publish(m);
    }
    ros::WallDuration(0.5).sleep();
  }

  // Publishes one frame and waits for its markers, the end of the chain.
  bool playFrame(const ret3d::DetectionArray::Ptr& detections) {
    const std::size_t before = markers_.size();
    detections_pub_.publish(detections);
    return test::waitFor([&] { return markers_.size() > before; }, 10.0);
  }

  test::TempDir tmp_;
  test::TinySequence seq_;
  std::string bag_;
  BagFrames frames_;
  test::LogCapture log_;
  ros::NodeHandle nh_;
  ros::Publisher detections_pub_, tf_pub_, tf_static_pub_;
  test::Inbox<ret3d::DetectionArray> intra_, tracked_;
  test::Inbox<ret3d::Object3DArray> objects_;
  test::Inbox<visualization_msgs::MarkerArray> markers_;
  test::Inbox<vision_msgs::Detection3DArray> detections_;
};

TEST_F(PipelineChain, EveryFrameThroughEveryStageWithStableIds) {
  ros::AsyncSpinner spinner(2);
  spinner.start();
  nodelet::Loader loader(false);
  startPipeline(loader);
  for (int f = 0; f < kFrames; ++f) {
    ASSERT_TRUE(playFrame(asDetections(*frames_.objects[f]))) << "frame " << f << "\n" << log_.all();
  }
  ASSERT_TRUE(test::waitFor([&] { return objects_.size() == kFrames; }, 5.0));
  const auto intra = intra_.all();
  const auto tracked = tracked_.all();
  const auto objects = objects_.all();
  const auto markers = markers_.all();
  ASSERT_EQ(intra.size(), static_cast<std::size_t>(kFrames));
  ASSERT_EQ(tracked.size(), static_cast<std::size_t>(kFrames));
  ASSERT_EQ(objects.size(), static_cast<std::size_t>(kFrames));
  ASSERT_EQ(markers.size(), static_cast<std::size_t>(kFrames));

  std::map<ObjectClass, std::uint32_t> ids;
  for (int f = 0; f < kFrames; ++f) {
    const std_msgs::Header& in = frames_.objects[f]->header;
    for (const std_msgs::Header* h : {&intra[f]->header, &tracked[f]->header, &objects[f]->header}) {
      EXPECT_EQ(h->stamp, in.stamp) << "frame " << f;
      EXPECT_EQ(h->frame_id, in.frame_id) << "frame " << f;
    }
    ASSERT_EQ(objects[f]->objects.size(), 2u) << "frame " << f;
    for (const Box& b : fromMsg(*objects[f])) {
      ASSERT_GT(b.track_id, 0u) << className(b.label) << " in frame " << f;
      if (f == 0) ids[b.label] = b.track_id;
      EXPECT_EQ(b.track_id, ids[b.label]) << className(b.label) << " changed id in frame " << f;
      // Untrained relation stages refine by (nearly) the identity: the boxes stay where the ground truth is.
      const Box& gt = b.label == ObjectClass::Car ? seq_.boxes[f][0] : seq_.boxes[f][1];
      EXPECT_NEAR(b.x, gt.x, 0.5);
      EXPECT_NEAR(b.y, gt.y, 0.5);
    }
    // Markers: DELETEALL first, in the input's frame and stamp.
    const auto& mk = markers[f]->markers;
    ASSERT_FALSE(mk.empty());
    EXPECT_EQ(mk.front().action, visualization_msgs::Marker::DELETEALL);
    for (std::size_t i = 1; i < mk.size(); ++i) {
      EXPECT_EQ(mk[i].header.frame_id, in.frame_id);
      EXPECT_EQ(mk[i].header.stamp, in.stamp);
    }
  }
  EXPECT_NE(ids[ObjectClass::Car], ids[ObjectClass::Pedestrian]);

  // The last frame's markers: a green box and a "Car #id" label for the car, a magenta box for the pedestrian, trails
  // for both, a velocity arrow for the moving car (it moves 1.5 m per frame over ground).
  const auto& mk = markers.back()->markers;
  int green_boxes = 0, magenta_boxes = 0, trails = 0, arrows = 0;
  bool car_label = false;
  for (const auto& m : mk) {
    if (m.ns == "boxes" && m.type == visualization_msgs::Marker::LINE_LIST) {
      EXPECT_EQ(m.points.size(), 28u);
      if (m.color.r == 0.0f && m.color.g == 1.0f && m.color.b == 0.0f) ++green_boxes;
      if (m.color.r == 1.0f && m.color.g == 0.0f && m.color.b == 1.0f) ++magenta_boxes;
    }
    if (m.ns == "labels" && m.text.find("Car #" + std::to_string(ids[ObjectClass::Car])) == 0) car_label = true;
    if (m.ns == "trails") ++trails;
    if (m.ns == "velocity") ++arrows;
  }
  EXPECT_EQ(green_boxes, 1);
  EXPECT_EQ(magenta_boxes, 1);
  EXPECT_TRUE(car_label);
  EXPECT_EQ(trails, 2);
  EXPECT_GE(arrows, 1);
}

TEST_F(PipelineChain, MissingTransformAndBackwardsStampsKeepItRunning) {
  ros::AsyncSpinner spinner(2);
  spinner.start();
  nodelet::Loader loader(false);
  startPipeline(loader);
  // A sensor frame tf has never heard of: every frame still comes out, and the nodelets say what they did.
  for (int f = 0; f < 3; ++f) {
    auto d = asDetections(*frames_.objects[f]);
    d->header.frame_id = "lidar_without_tf";
    ASSERT_TRUE(playFrame(d)) << "frame " << f;
  }
  EXPECT_NE(test::waitFor([&] { return !log_.find({"no transform", "lidar_without_tf", "odom"}).empty(); }, 2.0),
            false)
      << log_.all();
  const auto objects = objects_.all();
  ASSERT_EQ(objects.size(), 3u);
  for (const auto& o : objects) {
    EXPECT_EQ(o->header.frame_id, "lidar_without_tf");
    EXPECT_EQ(o->objects.size(), 2u);
  }
  // Stamps going backwards (a bag loop): the frames still come out, the tracker and InterRM reset and say so.
  for (int f : {4, 5, 1, 2}) {
    ASSERT_TRUE(playFrame(asDetections(*frames_.objects[f]))) << "frame " << f;
  }
  ASSERT_TRUE(test::waitFor([&] { return objects_.size() == 7u; }, 5.0));
  EXPECT_EQ(objects_.all().back()->header.stamp, frames_.objects[2]->header.stamp);
  EXPECT_FALSE(log_.find({"tracker reset"}).empty()) << log_.all();
  EXPECT_FALSE(log_.find({"stamp went backwards", "histories cleared"}).empty()) << log_.all();
}

// What a ROS command line tool prints (stdout and stderr), trimmed; empty when it failed.
std::string toolOutput(const std::vector<std::string>& args, const std::string& log) {
  std::filesystem::remove(log);  // the child appends to it
  if (test::runLogged(args, log, 20.0) != 0) return "";
  std::string out = test::readText(log);
  while (!out.empty() && std::isspace(static_cast<unsigned char>(out.back()))) out.pop_back();
  return out;
}

TEST_F(PipelineChain, ObjectsAlsoComeAsVisionMsgsDetections) {
  ros::AsyncSpinner spinner(2);
  spinner.start();
  nodelet::Loader loader(false);
  startPipeline(loader);
  auto& detections = detections_;
  ASSERT_TRUE(test::waitFor([&] { return detections.sub.getNumPublishers() > 0; }, 10.0));
  for (int f = 0; f < kFrames; ++f) {
    ASSERT_TRUE(playFrame(asDetections(*frames_.objects[f]))) << "frame " << f << "\n" << log_.all();
  }
  ASSERT_TRUE(test::waitFor([&] { return detections.size() == kFrames; }, 5.0)) << detections.size();
  // Every Detection3D matches the object of the Object3DArray with the same stamp: class, score, box.
  std::map<ros::Time, ret3d::Object3DArray::ConstPtr> objects;
  for (const auto& o : objects_.all()) objects[o->header.stamp] = o;
  for (const auto& d : detections.all()) {
    ASSERT_EQ(objects.count(d->header.stamp), 1u) << "no /objects at " << d->header.stamp;
    const ret3d::Object3DArray& o = *objects[d->header.stamp];
    EXPECT_EQ(d->header.frame_id, o.header.frame_id);
    ASSERT_EQ(d->detections.size(), o.objects.size());
    ASSERT_EQ(d->detections.size(), 2u);
    for (std::size_t i = 0; i < o.objects.size(); ++i) {
      const vision_msgs::Detection3D& det = d->detections[i];
      const Box want = fromMsg(o.objects[i]);
      EXPECT_EQ(det.header.stamp, o.header.stamp);
      ASSERT_EQ(det.results.size(), 1u);
      EXPECT_EQ(det.results[0].id, static_cast<int>(want.label));  // 1 Car, 2 Pedestrian, 3 Cyclist
      EXPECT_DOUBLE_EQ(det.results[0].score, want.score);
      ret3d::Object3D as_object;  // the detection's box read back as a Box
      as_object.pose = det.bbox.center;
      as_object.dimensions = det.bbox.size;
      const Box got = fromMsg(as_object);
      test::expectSameCentreAndSize(got, want, 1e-9);
      EXPECT_NEAR(got.yaw, want.yaw, 1e-9);
    }
  }
  // On the graph: upstream vision_msgs' type and md5, as the ROS tools report them.
  EXPECT_EQ(toolOutput({"rostopic", "type", "/objects/detections"}, tmp_ / "rostopic.log"),
            "vision_msgs/Detection3DArray");
  for (const auto& [type, md5] : test::upstreamVisionMsgsMd5()) {
    EXPECT_EQ(toolOutput({"rosmsg", "md5", type}, tmp_ / "rosmsg.log"), md5) << type;
  }
  EXPECT_EQ(ros::message_traits::MD5Sum<vision_msgs::Detection3DArray>::value(),
            test::upstreamVisionMsgsMd5().front().second);
}

TEST_F(PipelineChain, NoDetectionsTopicWhenSwitchedOff) {
  ros::param::set("/ret3d_inter/publish_detections", false);
  ros::AsyncSpinner spinner(2);
  spinner.start();
  nodelet::Loader loader(false);
  startPipeline(loader);
  for (int f = 0; f < 3; ++f) ASSERT_TRUE(playFrame(asDetections(*frames_.objects[f]))) << "frame " << f;
  ASSERT_TRUE(test::waitFor([&] { return objects_.size() == 3u; }, 5.0));
  EXPECT_EQ(detections_.sub.getNumPublishers(), 0u);
  EXPECT_EQ(detections_.size(), 0u);
}

// A nodelet that cannot run as configured refuses to start and says why.
class PipelineStart : public ::testing::Test {
 protected:
  void TearDown() override {
    ros::param::del("/bad");
    ros::param::del("/bad_tracker");
  }
  // Loads `type` as /bad and expects a refusal whose log line holds every part of `said`.
  void expectRefusal(const std::string& type, const std::vector<std::string>& said) {
    nodelet::Loader loader(false);
    EXPECT_FALSE(test::loadNodelet(loader, "/bad", type));
    std::vector<std::string> parts = said;
    parts.insert(parts.begin(), "refuses to start");
    EXPECT_FALSE(log_.find(parts).empty()) << "log:\n" << log_.all();
  }
  test::TempDir tmp_;
  test::LogCapture log_;
};

TEST_F(PipelineStart, InvalidTrackerOptionIsNamed) {
  XmlRpc::XmlRpcValue tracker;
  tracker["max_age"] = -3;
  ros::param::set("/bad/tracker", tracker);
  expectRefusal("ret3d/TrackerNodelet", {"/bad/tracker", "max_age", "-3"});
}

TEST_F(PipelineStart, InvalidNumberIsNamedWithItsRange) {
  ros::param::set("/bad/tf_timeout", -1.0);
  expectRefusal("ret3d/MarkerNodelet", {"/bad/tf_timeout", "-1", "must lie in [0, 5]"});
}

TEST_F(PipelineStart, MissingModelFileIsNamed) {
  ros::param::set("/bad/model_path", tmp_ / "no_such_model.pt");
  expectRefusal("ret3d/IntraRMNodelet", {"/bad/model_path", "no_such_model.pt"});
}

TEST_F(PipelineStart, CorruptModelFileIsRefused) {
  relation::InterRMArch arch;
  arch.c_enc = 32;
  arch.heads = 4;
  relation::InterRM(arch, 1).save(tmp_ / "inter.pt");
  // Truncated to half: the loader must notice.
  const std::string path = tmp_ / "inter.pt";
  std::string bytes;
  {
    std::ifstream in(path, std::ios::binary);
    bytes.assign(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
  }
  std::ofstream(tmp_ / "corrupt.pt", std::ios::binary).write(bytes.data(), bytes.size() / 2);
  ros::param::set("/bad/model_path", tmp_ / "corrupt.pt");
  expectRefusal("ret3d/InterRMNodelet", {"/bad/model_path", "corrupt.pt"});
}

// InterRM's histories age out with the tracker's max_age, read from the tracker nodelet's own parameters
// (~tracker_node names it): a tracker option the tracker would refuse stops InterRM too, naming it.
TEST_F(PipelineStart, InterRMReadsTheTrackersOptions) {
  XmlRpc::XmlRpcValue tracker;
  tracker["max_age"] = -3;
  ros::param::set("/bad_tracker/tracker", tracker);
  ros::param::set("/bad/tracker_node", std::string("bad_tracker"));
  expectRefusal("ret3d/InterRMNodelet", {"/bad_tracker/tracker", "max_age", "-3"});
}

// A ~max_age left over from older parameter files is ignored, and the warning says whose max_age applies.
TEST_F(PipelineStart, InterRMIgnoresItsOwnMaxAgeAndSaysSo) {
  relation::InterRMArch arch;
  arch.c_enc = 32;
  arch.heads = 4;
  relation::InterRM(arch, 1).save(tmp_ / "inter.pt");
  XmlRpc::XmlRpcValue tracker;
  tracker["max_age"] = 4;
  ros::param::set("/bad_tracker/tracker", tracker);
  ros::param::set("/bad/tracker_node", std::string("bad_tracker"));
  ros::param::set("/bad/model_path", tmp_ / "inter.pt");
  ros::param::set("/bad/max_age", 9);
  nodelet::Loader loader(false);
  ASSERT_TRUE(test::loadNodelet(loader, "/bad", "ret3d/InterRMNodelet")) << log_.all();
  EXPECT_FALSE(log_.find({"/bad/max_age", "ignored", "the tracker's max_age 4", "/bad_tracker/tracker_config"}).empty())
      << log_.all();
}

TEST_F(PipelineStart, WrongParameterTypeIsNamed) {
  ros::param::set("/bad/threads", std::string("many"));
  expectRefusal("ret3d/InterRMNodelet", {"/bad/threads", "many", "integer"});
}

}  // namespace
}  // namespace ret3d
