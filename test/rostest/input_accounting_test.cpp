// rostest (test/rostest/input_accounting_test.test): input accounting of the whole pipeline. The detector, IntraRM,
// tracker, InterRM and marker nodelets run in one real nodelet manager (in-process nodelet::Loader) with real,
// untrained model files (test/support/tiny_models.h). Eight awkward inputs are played at about 10 Hz: an empty cloud,
// no intensity field, uint8 intensity, NaN points, big-endian, an Ouster layout (organized, padded, extra fields), a
// million points and stamps going backwards. From the nodelets' own /diagnostics alone it checks that every cloud is
// answered or dropped under a named reason (frames in == frames out + the dropped.* counts, every stage), that each
// stage took in what the stage before it put out (nothing lost silently between them), and that what was worked around
// is counted under its kind (degraded.empty, degraded.over_point_limit, ...). A burst of clouds faster than the
// detector leaves no queue: what it skips is counted as dropped.superseded and the newest cloud is always answered. No
// timed assertion: every wait is for a condition, with generous timeouts.
#include <diagnostic_msgs/DiagnosticArray.h>
#include <gtest/gtest.h>
#include <ros/ros.h>
#include <sensor_msgs/PointCloud2.h>
#include <tf2_msgs/TFMessage.h>

#include <cmath>
#include <functional>
#include <iostream>
#include <map>
#include <mutex>
#include <string>
#include <vector>

#include "ret3d/DetectionArray.h"
#include "ret3d/ros/conversions.h"
#include "support/ros_test_util.h"
#include "support/test_util.h"
#include "support/tiny_models.h"
#include "support/tiny_sequence.h"

namespace ret3d {
namespace {

const std::vector<std::string> kStages = {"ret3d_detector", "ret3d_intra", "ret3d_tracker", "ret3d_inter",
                                          "ret3d_markers"};

// The last /diagnostics report of each nodelet, as numbers (the accounting keys are all counts).
class Diagnostics {
 public:
  void listen(ros::NodeHandle& nh) {
    sub_ = nh.subscribe<diagnostic_msgs::DiagnosticArray>(
        "/diagnostics", 100, [this](const diagnostic_msgs::DiagnosticArray::ConstPtr& msg) {
          std::lock_guard<std::mutex> lock(mutex_);
          for (const auto& s : msg->status) {
            std::string node = s.name.substr(0, s.name.find(':'));  // "/ret3d_detector: ..." -> "ret3d_detector"
            if (!node.empty() && node.front() == '/') node.erase(0, 1);
            std::map<std::string, double>& values = last_[node];
            values.clear();
            for (const auto& kv : s.values) {
              try {
                values[kv.key] = std::stod(kv.value);
              } catch (const std::exception&) {
              }
            }
          }
        });
  }
  std::map<std::string, double> of(const std::string& node) const {
    std::lock_guard<std::mutex> lock(mutex_);
    const auto it = last_.find(node);
    return it == last_.end() ? std::map<std::string, double>() : it->second;
  }

 private:
  mutable std::mutex mutex_;
  std::map<std::string, std::map<std::string, double>> last_;
  ros::Subscriber sub_;
};

double get(const std::map<std::string, double>& v, const std::string& key) {
  const auto it = v.find(key);
  return it == v.end() ? 0.0 : it->second;
}

double droppedSum(const std::map<std::string, double>& v) {
  double sum = 0;
  for (const auto& [key, n] : v) {
    if (key.rfind("dropped.", 0) == 0) sum += n;
  }
  return sum;
}

// Quiet: the detector has taken in `sent` clouds, and every stage has answered or dropped all it took in, the last
// one having taken in all its predecessor put out.
bool quiet(const Diagnostics& diagnostics, double sent) {
  double previous_out = sent;
  for (const std::string& stage : kStages) {
    const auto v = diagnostics.of(stage);
    if (v.empty() || get(v, "frames in") != previous_out) return false;
    if (get(v, "frames in") != get(v, "frames out") + droppedSum(v)) return false;
    previous_out = get(v, "frames out");
  }
  return true;
}

std::string describe(const Diagnostics& diagnostics) {
  std::string s;
  for (const std::string& stage : kStages) {
    s += stage + ":";
    for (const auto& [key, n] : diagnostics.of(stage)) {
      if (key.rfind("frames", 0) == 0 || key.rfind("dropped.", 0) == 0 || key.rfind("degraded.", 0) == 0) {
        s += " " + key + "=" + std::to_string(static_cast<long long>(n));
      }
    }
    s += "\n";
  }
  return s;
}

class InputAccountingTest : public ::testing::Test {
 protected:
  void SetUp() override {
    test::writeTinyModels(tmp_.path(), RET3D_SOURCE_DIR);
    ros::param::set("/ret3d_detector/config", tmp_ / "detector.yaml");
    ros::param::set("/ret3d_detector/model_path", tmp_ / "detector.pt");
    ros::param::set("/ret3d_detector/threads", 1);
    ros::param::set("/ret3d_intra/model_path", tmp_ / "intra_rm.pt");
    ros::param::set("/ret3d_intra/threads", 1);
    ros::param::set("/ret3d_tracker/tracker_config", std::string(RET3D_SOURCE_DIR) + "/config/tracker.yaml");
    ros::param::set("/ret3d_inter/model_path", tmp_ / "inter_rm.pt");
    ros::param::set("/ret3d_inter/threads", 1);
    seq_.write(tmp_.path(), "0000", 3, /*with_labels=*/false);
  }
  void TearDown() override {
    for (const std::string& stage : kStages) ros::param::del("/" + stage);
  }

  // odom -> velodyne, static: the pose is found at any stamp, backwards ones included.
  ros::Publisher publishStaticTf(ros::NodeHandle& nh) {
    ros::Publisher tf = nh.advertise<tf2_msgs::TFMessage>("/tf_static", 1, /*latch=*/true);
    tf2_msgs::TFMessage m;
    geometry_msgs::TransformStamped ts;
    ts.header.frame_id = "odom";
    ts.child_frame_id = "velodyne";
    ts.transform.rotation.w = 1.0;
    m.transforms.push_back(ts);
    tf.publish(m);
    return tf;
  }

  test::TempDir tmp_;
  test::TinySequence seq_;
  test::LogCapture log_;
};

TEST_F(InputAccountingTest, EveryAwkwardCloudIsAnsweredOrCountedUnderItsReasonThroughThePipeline) {
  ros::NodeHandle nh;
  ros::AsyncSpinner spinner(2);
  spinner.start();
  nodelet::Loader loader(false);
  const std::vector<std::string> types = {"ret3d/DetectorNodelet", "ret3d/IntraRMNodelet", "ret3d/TrackerNodelet",
                                          "ret3d/InterRMNodelet", "ret3d/MarkerNodelet"};
  for (std::size_t k = 0; k < kStages.size(); ++k) {
    ASSERT_TRUE(test::loadNodelet(loader, "/" + kStages[k], types[k])) << log_.all();
  }
  Diagnostics diagnostics;
  diagnostics.listen(nh);
  const ros::Publisher tf = publishStaticTf(nh);
  ros::Publisher points = nh.advertise<sensor_msgs::PointCloud2>("/points", 10);
  ASSERT_TRUE(test::waitFor([&] { return points.getNumSubscribers() > 0 && quiet(diagnostics, 0); }, 60.0))
      << describe(diagnostics) << log_.all();

  constexpr int kCloudsPerCase = 5;
  PointCloud nan_points = seq_.scans[1];
  for (std::size_t i = 0; i < nan_points.size(); i += 7) nan_points.points[i].x = std::nanf("");
  const PointCloud big = test::millionPointCloud();
  struct Case {
    std::string name;
    std::function<sensor_msgs::PointCloud2(const std_msgs::Header&)> make;
    std::string degraded;  // the kind every answered cloud of the case is counted under ("" : none expected)
    bool backwards = false;
  };
  const std::vector<Case> cases = {
      {"empty", [&](const std_msgs::Header& h) { return toPointCloud2(PointCloud(), h); }, "degraded.empty"},
      {"no intensity", [&](const std_msgs::Header& h) { return test::xyzCloud(seq_.scans[0], h); },
       "degraded.conversion"},
      {"uint8 intensity", [&](const std_msgs::Header& h) { return test::uint8IntensityCloud(seq_.scans[1], h); }, ""},
      {"NaN points", [&](const std_msgs::Header& h) { return toPointCloud2(nan_points, h); },
       "degraded.nonfinite_points"},
      {"big-endian", [&](const std_msgs::Header& h) { return test::bigEndianCloud(seq_.scans[2], h); }, ""},
      {"Ouster layout", [&](const std_msgs::Header& h) { return test::ousterCloud(seq_.scans[0], h); }, ""},
      {"1,000,000 points", [&](const std_msgs::Header& h) { return toPointCloud2(big, h); },
       "degraded.over_point_limit"},
      {"stamps backwards", [&](const std_msgs::Header& h) { return toPointCloud2(seq_.scans[1], h); },
       "degraded.stamp_backwards", true},
  };

  double sent = 0, t = 1.0e9;
  for (const Case& c : cases) {
    // Built before they are played, so that the rate is the player's, not the message building's.
    std::vector<sensor_msgs::PointCloud2::Ptr> clouds;
    for (int i = 0; i < kCloudsPerCase; ++i) {
      std_msgs::Header h;
      h.frame_id = "velodyne";
      // Backwards: each stamp before every stamp sent so far.
      h.stamp = ros::Time(c.backwards ? 1.0e9 - 10.0 - 0.1 * i : (t += 0.1));
      clouds.push_back(boost::make_shared<sensor_msgs::PointCloud2>(c.make(h)));
    }
    const auto before = diagnostics.of("ret3d_detector");
    for (const auto& cloud : clouds) {
      points.publish(cloud);
      ros::WallDuration(0.1).sleep();  // about 10 Hz; what the detector cannot keep up with is superseded
    }
    sent += kCloudsPerCase;
    ASSERT_TRUE(test::waitFor([&] { return quiet(diagnostics, sent); }, 90.0))
        << c.name << ": not every cloud answered or counted\n"
        << describe(diagnostics) << log_.all();
    const auto after = diagnostics.of("ret3d_detector");
    const double answered = get(after, "frames out") - get(before, "frames out");
    const double superseded = get(after, "dropped.superseded") - get(before, "dropped.superseded");
    std::cout << c.name << ": " << answered << " of " << kCloudsPerCase << " answered, " << superseded
              << " superseded" << std::endl;
    EXPECT_EQ(answered + superseded, kCloudsPerCase) << c.name << "\n" << describe(diagnostics);
    EXPECT_GE(answered, 1) << c.name << ": the newest cloud is always answered\n" << describe(diagnostics);
    if (!c.degraded.empty()) {
      EXPECT_EQ(get(after, c.degraded) - get(before, c.degraded), answered)
          << c.name << ": every answered cloud counted under " << c.degraded << "\n"
          << describe(diagnostics);
    }
  }
  // Nothing was too old (~max_input_age is off by default) and no stage failed.
  for (const std::string& stage : kStages) {
    EXPECT_EQ(get(diagnostics.of(stage), "dropped.too_old"), 0) << stage;
    EXPECT_EQ(get(diagnostics.of(stage), "dropped.error"), 0) << stage << "\n" << log_.all();
  }
  EXPECT_FALSE(log_.find({"1000000 points", "~max_points 500000", "thinned evenly", "500000 points kept"}).empty())
      << log_.all();
}

TEST_F(InputAccountingTest, ABurstFasterThanTheDetectorLeavesNoQueueAndWhatItSkipsIsCounted) {
  ros::NodeHandle nh;
  ros::AsyncSpinner spinner(2);
  spinner.start();
  // Clouds stamped in the future are never too old; the one stamped a minute ago at the end is.
  ros::param::set("/ret3d_detector/max_input_age", 10.0);
  nodelet::Loader loader(false);
  ASSERT_TRUE(test::loadNodelet(loader, "/ret3d_detector", "ret3d/DetectorNodelet")) << log_.all();
  Diagnostics diagnostics;
  diagnostics.listen(nh);
  const ros::Publisher tf = publishStaticTf(nh);
  test::Inbox<ret3d::DetectionArray> detections;
  detections.listen(nh, "/detections");
  ros::Publisher points = nh.advertise<sensor_msgs::PointCloud2>("/points", 10);
  ASSERT_TRUE(test::waitFor(
      [&] { return points.getNumSubscribers() > 0 && detections.sub.getNumPublishers() > 0; }, 30.0));

  // Ten clouds back to back (as many as the subscriber's queue holds), a million-point one first: whether the worker
  // takes it before the others arrive (and is busy with it for far longer than they take) or not, it cannot keep up.
  std::vector<sensor_msgs::PointCloud2::Ptr> burst;
  std_msgs::Header h;
  h.frame_id = "velodyne";
  double t = 3.0e9;
  h.stamp = ros::Time(t);
  burst.push_back(boost::make_shared<sensor_msgs::PointCloud2>(toPointCloud2(test::millionPointCloud(), h)));
  for (int i = 0; i < 9; ++i) {
    h.stamp = ros::Time(t += 0.1);
    burst.push_back(boost::make_shared<sensor_msgs::PointCloud2>(toPointCloud2(seq_.scans[i % 3], h)));
  }
  for (const auto& cloud : burst) points.publish(cloud);

  const double sent = static_cast<double>(burst.size());
  auto settled = [&] {
    const auto v = diagnostics.of("ret3d_detector");
    return get(v, "frames in") == sent && get(v, "frames in") == get(v, "frames out") + droppedSum(v);
  };
  ASSERT_TRUE(test::waitFor(settled, 90.0)) << describe(diagnostics) << log_.all();
  const auto v = diagnostics.of("ret3d_detector");
  const double answered = get(v, "frames out"), superseded = get(v, "dropped.superseded");
  EXPECT_EQ(answered + superseded, sent) << describe(diagnostics);
  std::cout << "burst: " << answered << " of " << sent << " answered, " << superseded << " superseded" << std::endl;
  EXPECT_GE(superseded, 1) << "no cloud skipped: the burst was queued\n" << describe(diagnostics);
  // The outputs came for the clouds the diagnostics call answered, in order, and the last is the newest cloud.
  ASSERT_TRUE(test::waitFor([&] { return static_cast<double>(detections.size()) == answered; }, 30.0));
  const auto out = detections.all();
  EXPECT_EQ(out.back()->header.stamp, burst.back()->header.stamp);
  for (std::size_t i = 1; i < out.size(); ++i) EXPECT_LT(out[i - 1]->header.stamp, out[i]->header.stamp);

  // Older than ~max_input_age: dropped and counted as too_old, not answered late.
  h.stamp = ros::Time::now() - ros::Duration(60.0);
  points.publish(boost::make_shared<sensor_msgs::PointCloud2>(toPointCloud2(seq_.scans[0], h)));
  ASSERT_TRUE(test::waitFor([&] { return get(diagnostics.of("ret3d_detector"), "dropped.too_old") == 1; }, 30.0))
      << describe(diagnostics);
  EXPECT_EQ(get(diagnostics.of("ret3d_detector"), "frames out"), answered);
  EXPECT_FALSE(log_.find({"s old (> ~max_input_age 10", "dropped"}).empty()) << log_.all();
}

}  // namespace
}  // namespace ret3d
