// rostest (test/rostest/pipeline_detector_test.test): the DetectorNodelet in a real nodelet manager (in-process
// nodelet::Loader) with a real model file (a freshly initialised LWD-3D network saved by the model's own save
// function, on a small BEV grid so that the test is quick on 2 cores). It is fed clouds a user may have: the velodyne
// layout with tf, an Ouster layout (organized, padded, float intensity in the thousands, uint32 time), no intensity,
// empty, all NaN, a million points, stamps going backwards, a frame without tf. For every cloud a DetectionArray comes
// out with the cloud's stamp and frame id, and the nodelet says what it worked around. A model that does not fit the
// configuration, or a missing one, makes it refuse to start with a message naming the parameter.
#include <dynamic_reconfigure/DoubleParameter.h>
#include <dynamic_reconfigure/Reconfigure.h>
#include <gtest/gtest.h>
#include <ros/ros.h>
#include <sensor_msgs/PointCloud2.h>
#include <tf2_msgs/TFMessage.h>

#include <cmath>
#include <cstring>
#include <fstream>
#include <mutex>
#include <sstream>

#include "ret3d/DetectionArray.h"
#include "ret3d/core/transform.h"
#include "ret3d/detector/detector.h"
#include "ret3d/detector/nn/model.h"
#include "ret3d/ros/conversions.h"
#include "support/ros_test_util.h"
#include "support/test_util.h"
#include "support/tiny_models.h"
#include "support/tiny_sequence.h"

namespace ret3d {
namespace {

class DetectorNodeletTest : public ::testing::Test {
 protected:
  void SetUp() override {
    ASSERT_FALSE(source_dir_.empty()) << "RET3D_PACKAGE_DIR not set (test/rostest/pipeline_detector_test.test sets it)";
    std::ofstream(tmp_ / "small.yaml") << test::smallDetectorConfig(source_dir_);
    DetectorOptions options = loadDetectorOptions(tmp_ / "small.yaml");
    options.inference.threads = 1;
    Detector fresh(options);  // empty model path: a freshly initialised network
    fresh.model().save(tmp_ / "detector.pt");
    ros::param::set("/ret3d_detector/config", tmp_ / "small.yaml");
    ros::param::set("/ret3d_detector/model_path", tmp_ / "detector.pt");
    ros::param::set("/ret3d_detector/threads", 1);
    seq_.write(tmp_.path(), "0000", 3, /*with_labels=*/false);
  }
  void TearDown() override { ros::param::del("/ret3d_detector"); }

  // rostest nodes are not given RET3D_SOURCE_DIR; the .test file passes the package's folder.
  std::string source_dir_ = std::getenv("RET3D_PACKAGE_DIR") ? std::getenv("RET3D_PACKAGE_DIR") : "";
  test::TempDir tmp_;
  test::TinySequence seq_;
  test::LogCapture log_;
};

TEST_F(DetectorNodeletTest, EveryCloudGivesDetectionsAndWhatWasDoneIsSaid) {
  ros::NodeHandle nh;
  ros::AsyncSpinner spinner(2);
  spinner.start();
  nodelet::Loader loader(false);
  ASSERT_TRUE(test::loadNodelet(loader, "/ret3d_detector", "ret3d/DetectorNodelet")) << log_.all();

  std::mutex mutex;
  std::vector<ret3d::DetectionArray::ConstPtr> out;
  ros::Subscriber sub = nh.subscribe<ret3d::DetectionArray>(
      "/detections", 100, [&](const ret3d::DetectionArray::ConstPtr& m) {
        std::lock_guard<std::mutex> lock(mutex);
        out.push_back(m);
      });
  ros::Publisher points = nh.advertise<sensor_msgs::PointCloud2>("/points", 10);
  ros::Publisher tf = nh.advertise<tf2_msgs::TFMessage>("/tf", 100);
  ASSERT_TRUE(test::waitFor(
      [&] { return points.getNumSubscribers() > 0 && sub.getNumPublishers() > 0 && tf.getNumSubscribers() > 0; },
      10.0));

  double t = 1.0e9;
  // odom -> velodyne at t: driving forward 1 m per 0.1 s.
  auto publishTf = [&](double stamp, double x) {
    tf2_msgs::TFMessage m;
    geometry_msgs::TransformStamped ts;
    ts.header.stamp = ros::Time(stamp);
    ts.header.frame_id = "odom";
    ts.child_frame_id = "velodyne";
    ts.transform.translation.x = x;
    ts.transform.rotation.w = 1.0;
    m.transforms.push_back(ts);
    tf.publish(m);
  };
  std::size_t sent = 0;
  auto send = [&](const sensor_msgs::PointCloud2& cloud, const std::string& what) {
    const std::size_t before = [&] {
      std::lock_guard<std::mutex> lock(mutex);
      return out.size();
    }();
    points.publish(boost::make_shared<sensor_msgs::PointCloud2>(cloud));
    ++sent;
    const bool ok = test::waitFor(
        [&] {
          std::lock_guard<std::mutex> lock(mutex);
          return out.size() > before;
        },
        30.0);
    EXPECT_TRUE(ok) << "no detections for the " << what << " cloud\n" << log_.all();
    std::lock_guard<std::mutex> lock(mutex);
    if (ok) {
      EXPECT_EQ(out.back()->header.stamp, cloud.header.stamp) << what;
      EXPECT_EQ(out.back()->header.frame_id, cloud.header.frame_id) << what;
      EXPECT_EQ(out.back()->features.size(), out.back()->objects.size() * out.back()->feature_dim) << what;
    }
  };
  std_msgs::Header h;
  h.frame_id = "velodyne";

  // Two velodyne-layout sweeps with tf: the second uses the first, motion-compensated.
  for (int f = 0; f < 2; ++f) {
    h.stamp = ros::Time(t += 0.1);
    publishTf(h.stamp.toSec(), 1.0 * f);
    ros::WallDuration(0.05).sleep();
    send(toPointCloud2(seq_.scans[f], h), "velodyne");
  }
  // Ouster layout.
  h.stamp = ros::Time(t += 0.1);
  publishTf(h.stamp.toSec(), 2.0);
  ros::WallDuration(0.05).sleep();
  send(test::ousterCloud(seq_.scans[2], h), "Ouster");
  // No intensity.
  h.stamp = ros::Time(t += 0.1);
  publishTf(h.stamp.toSec(), 3.0);
  send(test::xyzCloud(seq_.scans[0], h), "no-intensity");
  EXPECT_FALSE(log_.find({"no intensity field"}).empty()) << log_.all();
  // Empty.
  h.stamp = ros::Time(t += 0.1);
  publishTf(h.stamp.toSec(), 4.0);
  send(toPointCloud2(PointCloud(), h), "empty");
  EXPECT_FALSE(log_.find({"empty cloud"}).empty()) << log_.all();
  // All NaN.
  PointCloud nan_cloud;
  for (int i = 0; i < 1000; ++i) {
    nan_cloud.points.push_back({std::nanf(""), std::nanf(""), std::nanf(""), 0.5f});
  }
  h.stamp = ros::Time(t += 0.1);
  publishTf(h.stamp.toSec(), 5.0);
  send(toPointCloud2(nan_cloud, h), "NaN");
  EXPECT_FALSE(log_.find({"dropped 1000 of 1000 points", "NaN"}).empty()) << log_.all();
  // A million points.
  h.stamp = ros::Time(t += 0.1);
  publishTf(h.stamp.toSec(), 6.0);
  send(toPointCloud2(test::millionPointCloud(), h), "1-million-point");
  // Stamps going backwards.
  h.stamp = ros::Time(t - 0.35);
  publishTf(h.stamp.toSec(), 2.5);
  send(toPointCloud2(seq_.scans[1], h), "backwards");
  EXPECT_FALSE(log_.find({"stamp went backwards"}).empty()) << log_.all();
  // A frame tf does not know, two sweeps in a row: no motion compensation, and said so.
  h.frame_id = "lidar_without_tf";
  for (int f = 0; f < 2; ++f) {
    h.stamp = ros::Time(t += 0.1);
    send(toPointCloud2(seq_.scans[f], h), "untransformed");
  }
  EXPECT_FALSE(log_.find({"no transform", "lidar_without_tf", "without motion compensation"}).empty()) << log_.all();
  std::lock_guard<std::mutex> lock(mutex);
  EXPECT_EQ(out.size(), sent);
}

TEST_F(DetectorNodeletTest, ThresholdsChangeAtRunTimeThroughDynamicReconfigure) {
  ros::AsyncSpinner spinner(2);
  spinner.start();
  nodelet::Loader loader(false);
  ASSERT_TRUE(test::loadNodelet(loader, "/ret3d_detector", "ret3d/DetectorNodelet")) << log_.all();
  ros::NodeHandle nh;
  std::mutex mutex;  // guards `out`, filled by the subscriber below
  std::vector<ret3d::DetectionArray::ConstPtr> out;
  auto keep = [&](const ret3d::DetectionArray::ConstPtr& m) {
    std::lock_guard<std::mutex> lock(mutex);
    out.push_back(m);
  };
  ros::Subscriber sub = nh.subscribe<ret3d::DetectionArray>("/detections", 100, keep);
  ros::Publisher points = nh.advertise<sensor_msgs::PointCloud2>("/points", 10);
  ASSERT_TRUE(test::waitFor([&] { return points.getNumSubscribers() > 0 && sub.getNumPublishers() > 0; }, 10.0));
  ASSERT_TRUE(ros::service::waitForService("/ret3d_detector/set_parameters", ros::Duration(10.0)));

  // Sets the score threshold (NMS at IoU 1: nothing suppressed) and returns the boxes of the next cloud.
  double t = 2.0e9;
  auto objectsAt = [&](double score_threshold) -> std::size_t {
    dynamic_reconfigure::Reconfigure srv;
    dynamic_reconfigure::DoubleParameter p;
    p.name = "score_threshold", p.value = score_threshold;
    srv.request.config.doubles.push_back(p);
    p.name = "nms_iou", p.value = 1.0;
    srv.request.config.doubles.push_back(p);
    EXPECT_TRUE(ros::service::call("/ret3d_detector/set_parameters", srv));
    for (const auto& d : srv.response.config.doubles)
      if (d.name == "score_threshold") EXPECT_DOUBLE_EQ(d.value, score_threshold);
    std_msgs::Header h;
    h.frame_id = "velodyne";
    h.stamp = ros::Time(t += 0.1);
    const std::size_t before = [&] {
      std::lock_guard<std::mutex> lock(mutex);
      return out.size();
    }();
    points.publish(boost::make_shared<sensor_msgs::PointCloud2>(toPointCloud2(seq_.scans[0], h)));
    EXPECT_TRUE(test::waitFor(
        [&] {
          std::lock_guard<std::mutex> lock(mutex);
          return out.size() > before;
        },
        30.0));
    std::lock_guard<std::mutex> lock(mutex);
    return out.back()->objects.size();
  };
  // The untrained network scores everything near its prior (~0.01): a zero threshold passes boxes, 1.0 none.
  EXPECT_GT(objectsAt(0.0), 0u);
  EXPECT_EQ(objectsAt(1.0), 0u);
  EXPECT_GT(objectsAt(0.0), 0u);
  EXPECT_FALSE(log_.find({"detector thresholds", "score_threshold 1"}).empty()) << log_.all();
  // A value InferenceOptions::validate() refuses (NaN passes the server's own clamping) changes nothing, with a
  // warning, and the server answers with the values in force.
  dynamic_reconfigure::Reconfigure srv;
  dynamic_reconfigure::DoubleParameter p;
  p.name = "nms_iou", p.value = std::nan("");
  srv.request.config.doubles.push_back(p);
  EXPECT_TRUE(ros::service::call("/ret3d_detector/set_parameters", srv));
  for (const auto& d : srv.response.config.doubles)
    if (d.name == "nms_iou") EXPECT_DOUBLE_EQ(d.value, 1.0);
  EXPECT_FALSE(log_.find({"dynamic_reconfigure refused", "nms_iou = nan: must lie in [0, 1]"}).empty()) << log_.all();
  EXPECT_GT(objectsAt(0.0), 0u);  // still running
}

TEST_F(DetectorNodeletTest, ModelThatDoesNotFitTheConfigIsRefused) {
  // The saved model is for the small grid; the default config describes another one.
  ros::param::set("/bad_detector/model_path", tmp_ / "detector.pt");
  ros::param::set("/bad_detector/config", source_dir_ + "/config/detector/lwd3d_center.yaml");
  nodelet::Loader loader(false);
  EXPECT_FALSE(test::loadNodelet(loader, "/bad_detector", "ret3d/DetectorNodelet"));
  EXPECT_FALSE(log_.find({"refuses to start", "/bad_detector/model_path", "detector.pt"}).empty()) << log_.all();
  ros::param::del("/bad_detector");
}

TEST_F(DetectorNodeletTest, TheGridExtentWidensTheGroundCoveredAndAWrongOneIsRefused) {
  // The model is for +-24 m; ~grid_extent runs it over 96 x 48 m.
  ros::param::set("/wide_detector/model_path", tmp_ / "detector.pt");
  ros::param::set("/wide_detector/config", tmp_ / "small.yaml");
  ros::param::set("/wide_detector/threads", 1);
  ros::param::set("/wide_detector/grid_extent", std::vector<double>{-48, 48, -24, 24});
  {
    nodelet::Loader loader(false);
    EXPECT_TRUE(test::loadNodelet(loader, "/wide_detector", "ret3d/DetectorNodelet")) << log_.all();
    EXPECT_FALSE(log_.find({"detector warmed up", "x [-48, 48] y [-24, 24]"}).empty()) << log_.all();
    loader.unload("/wide_detector");
  }
  ros::param::del("/wide_detector");
  // Two numbers, or an extent that is not a whole number of the network's coarsest cells (8 m here): refused.
  for (const auto& extent : {std::vector<double>{-48, 48}, std::vector<double>{-30, 30, -24, 24}}) {
    ros::param::set("/bad_detector/model_path", tmp_ / "detector.pt");
    ros::param::set("/bad_detector/config", tmp_ / "small.yaml");
    ros::param::set("/bad_detector/grid_extent", extent);
    nodelet::Loader loader(false);
    EXPECT_FALSE(test::loadNodelet(loader, "/bad_detector", "ret3d/DetectorNodelet"));
    EXPECT_FALSE(log_.find({"refuses to start", "/bad_detector/grid_extent"}).empty()) << log_.all();
    ros::param::del("/bad_detector");
  }
}

TEST_F(DetectorNodeletTest, APointLimitOutsideItsRangeIsRefused) {
  ros::param::set("/bad_detector/model_path", tmp_ / "detector.pt");
  ros::param::set("/bad_detector/config", tmp_ / "small.yaml");
  ros::param::set("/bad_detector/max_points", 10);
  nodelet::Loader loader(false);
  EXPECT_FALSE(test::loadNodelet(loader, "/bad_detector", "ret3d/DetectorNodelet"));
  EXPECT_FALSE(log_.find({"refuses to start", "/bad_detector/max_points = 10", "[1000, 10000000]"}).empty())
      << log_.all();
  ros::param::del("/bad_detector");
}

TEST_F(DetectorNodeletTest, MissingModelIsRefused) {
  ros::param::set("/bad_detector/model_path", tmp_ / "missing.pt");
  ros::param::set("/bad_detector/config", tmp_ / "small.yaml");
  nodelet::Loader loader(false);
  EXPECT_FALSE(test::loadNodelet(loader, "/bad_detector", "ret3d/DetectorNodelet"));
  EXPECT_FALSE(log_.find({"refuses to start", "/bad_detector/model_path", "missing.pt"}).empty()) << log_.all();
  ros::param::del("/bad_detector");
}

TEST_F(DetectorNodeletTest, WithoutConfigTheModelFilesOwnConfigIsUsed) {
  // A model saved with the config it was trained with runs without ~config (the launch file's default): an
  // anchor-head or a centre-head model alike, whichever the default model file holds.
  const std::string small = test::smallDetectorConfig(source_dir_);
  DetectorOptions options = detectorOptionsFromYaml(small);
  options.inference.threads = 1;
  Detector(options).model().save(tmp_ / "with_config.pt", small);
  ros::param::set("/own_detector/model_path", tmp_ / "with_config.pt");
  ros::param::set("/own_detector/config", "");
  ros::param::set("/own_detector/threads", 1);
  nodelet::Loader loader(false);
  EXPECT_TRUE(test::loadNodelet(loader, "/own_detector", "ret3d/DetectorNodelet")) << log_.all();
  loader.unload("/own_detector");
  ros::param::del("/own_detector");
}

TEST_F(DetectorNodeletTest, WithoutConfigAModelThatStoresNoneOrACorruptOneIsRefused) {
  // detector.pt was saved without its training config: nothing to run it with.
  ros::param::set("/bad_detector/model_path", tmp_ / "detector.pt");
  ros::param::set("/bad_detector/config", "");
  {
    nodelet::Loader loader(false);
    EXPECT_FALSE(test::loadNodelet(loader, "/bad_detector", "ret3d/DetectorNodelet"));
  }
  EXPECT_FALSE(log_.find({"refuses to start", "/bad_detector/model_path", "does not store the config"}).empty())
      << log_.all();
  // Not a model file at all.
  std::ofstream(tmp_ / "corrupt.pt") << "not a model";
  ros::param::set("/bad_detector/model_path", tmp_ / "corrupt.pt");
  {
    nodelet::Loader loader(false);
    EXPECT_FALSE(test::loadNodelet(loader, "/bad_detector", "ret3d/DetectorNodelet"));
  }
  EXPECT_FALSE(log_.find({"refuses to start", "/bad_detector/model_path", "corrupt.pt"}).empty()) << log_.all();
  ros::param::del("/bad_detector");
}

}  // namespace
}  // namespace ret3d
