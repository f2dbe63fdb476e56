// The nodelet bench's bag: its index read once (scanBag) and its clouds and /tf played by the player process
// (playBag) with the stamps moved to the wall clock (tools/nodelet_bench_parts.h).
#include <rosbag/bag.h>
#include <rosbag/view.h>
#include <sensor_msgs/PointCloud2.h>
#include <tf2_msgs/TFMessage.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <iostream>
#include <sstream>
#include <stdexcept>

#include "ret3d/ros/bag_reader.h"
#include "tools/nodelet_bench_parts.h"

namespace ret3d {
namespace tools {
namespace bench {

namespace fs = std::filesystem;

BagPlan scanBag(const NodeletBenchOptions& o) {
  if (!fs::is_regular_file(o.bag)) throw std::runtime_error(o.bag + ": no such file");
  BagPlan plan;
  try {
    rosbag::Bag bag;
    openCheckedBag(bag, o.bag);
    rosbag::View all(bag);
    for (const rosbag::ConnectionInfo* c : all.getConnections()) {
      if (c->datatype == "sensor_msgs/PointCloud2" && (o.topic.empty() ? plan.topic.empty() : c->topic == o.topic))
        plan.topic = c->topic;
      if (c->datatype == "tf2_msgs/TFMessage" && c->topic == kTf) plan.tf = true;
      if (c->datatype == "tf2_msgs/TFMessage" && c->topic == kTfStatic) plan.tf_static = true;
    }
    if (plan.topic.empty())
      throw std::runtime_error(o.topic.empty() ? "no sensor_msgs/PointCloud2 topic"
                                               : "no sensor_msgs/PointCloud2 messages on " + o.topic);
    rosbag::View clouds(bag, rosbag::TopicQuery(plan.topic));
    ros::Time first, last;
    for (const rosbag::MessageInstance& m : clouds) {
      if (plan.clouds == 0) {
        first = m.getTime();
        const auto msg = readBagMessage<sensor_msgs::PointCloud2>(m);
        if (!msg) throw std::runtime_error(plan.topic + ": the first message is no sensor_msgs/PointCloud2");
        const double skew = (msg->header.stamp - m.getTime()).toSec();
        // A driver's stamp is a little before its record time; seconds apart means another clock (e.g. a bag
        // re-recorded later): then the clouds' stamps set the schedule.
        plan.stamp_skew = std::abs(skew) > 1.0 ? skew : 0.0;
      }
      last = m.getTime();
      if (static_cast<int>(++plan.clouds) >= o.max_frames) break;
    }
    std::vector<std::string> topics = {plan.topic};
    if (plan.tf) topics.push_back(kTf);
    if (plan.tf_static) topics.push_back(kTfStatic);
    rosbag::View played(bag, rosbag::TopicQuery(topics));
    plan.start = played.size() ? played.begin()->getTime() : first;
    plan.start = std::min(plan.start, first);
    plan.duration = (last - plan.start).toSec();
    plan.first_cloud = (first - plan.start).toSec();
    if (plan.clouds > 1) plan.cloud_rate_hz = static_cast<double>(plan.clouds - 1) / std::max(1e-9, (last - first).toSec());
  } catch (const rosbag::BagException& e) {
    throw std::runtime_error(o.bag + ": " + e.what());
  } catch (const std::runtime_error& e) {
    throw std::runtime_error(o.bag + ": " + e.what());
  }
  if (plan.clouds <= static_cast<std::size_t>(std::max(0, o.warmup)))
    throw std::runtime_error(o.bag + ": " + std::to_string(plan.clouds) + " clouds on " + plan.topic +
                             ", not more than the " + std::to_string(o.warmup) + " warm-up frames (--warmup)");
  return plan;
}

// Plays the bag as `rosbag play` would, but with the stamps moved to the wall clock: bag time t (record time, or
// stamp minus skew) is published at start + (t - plan.start) / rate and stamped with that time. At rate 1 this is one
// constant offset; /tf gets the same mapping, so the detector's and the tracker's lookups at a cloud's stamp work.
// /tf_static is published as it is (latched). Waits for the manager's go (a byte on go_fd) first.
int playBag(const NodeletBenchOptions& o, const BagPlan& plan, int go_fd) {
  ros::M_string no_remappings;
  ros::init(no_remappings, "ret3d_bench_player", ros::init_options::NoSigintHandler);
  waitForMaster();
  ros::NodeHandle nh;
  ros::Publisher points = nh.advertise<sensor_msgs::PointCloud2>(kPoints, 1000);
  ros::Publisher tf = nh.advertise<tf2_msgs::TFMessage>(kTf, 1000);
  ros::Publisher tf_static = nh.advertise<tf2_msgs::TFMessage>(kTfStatic, 100, /*latch=*/true);
  char go = 0;
  if (read(go_fd, &go, 1) != 1) return 2;  // the manager ended before the run
  // Messages published before the manager has connected are lost: wait for its connections.
  const ros::WallTime connect_deadline = ros::WallTime::now() + ros::WallDuration(20.0);
  while (ros::ok() && ros::WallTime::now() < connect_deadline &&
         (points.getNumSubscribers() == 0 || (plan.tf && tf.getNumSubscribers() == 0) ||
          (plan.tf_static && tf_static.getNumSubscribers() == 0)))
    ros::WallDuration(0.01).sleep();
  if (points.getNumSubscribers() == 0) {
    std::cerr << "bench player: nobody subscribed to " << kPoints << " within 20 s\n";
    return 1;
  }

  const ros::Time start = ros::Time::now() + ros::Duration(0.2);
  auto wall = [&](const ros::Time& bag_time) {
    return start + ros::Duration((bag_time - plan.start).toSec() / o.rate);
  };
  auto waitUntil = [](const ros::Time& t) {
    const ros::Duration d = t - ros::Time::now();
    if (d > ros::Duration(0)) d.sleep();
  };
  rosbag::Bag bag(o.bag, rosbag::bagmode::Read);  // its layout checked by scanBag
  std::vector<std::string> topics = {plan.topic};
  if (plan.tf) topics.push_back(kTf);
  if (plan.tf_static) topics.push_back(kTfStatic);
  rosbag::View view(bag, rosbag::TopicQuery(topics));
  // --loop-frames: pass k is the bag shifted by k periods, a period being the clouds' span plus one cloud interval,
  // so the stamps keep increasing at the bag's rate across the seam (the ego pose jumps back to the bag's start).
  const std::size_t total = o.loop_frames > 0 ? static_cast<std::size_t>(o.loop_frames) : plan.clouds;
  const double period =
      plan.duration - plan.first_cloud + (plan.cloud_rate_hz > 0 ? 1.0 / plan.cloud_rate_hz : 0.1);
  std::size_t clouds = 0;
  for (int pass = 0; clouds < total && ros::ok(); ++pass) {
    const ros::Duration shift(pass * period);
    std::size_t in_pass = 0;
    for (const rosbag::MessageInstance& m : view) {
      if (!ros::ok()) break;
      if (m.getTopic() == plan.topic) {
        if (in_pass >= plan.clouds || clouds >= total) break;
        const auto msg = readBagMessage<sensor_msgs::PointCloud2>(m);
        if (!msg) continue;
        msg->header.stamp = wall(msg->header.stamp - ros::Duration(plan.stamp_skew) + shift);
        waitUntil(wall(m.getTime() + shift));
        points.publish(msg);
        ++clouds, ++in_pass;
      } else if (m.getTopic() == kTfStatic) {
        if (pass > 0) continue;  // latched: once is enough
        if (const auto msg = readBagMessage<tf2_msgs::TFMessage>(m)) tf_static.publish(msg);
      } else if (const auto msg = readBagMessage<tf2_msgs::TFMessage>(m)) {
        for (geometry_msgs::TransformStamped& t : msg->transforms)
          if (!t.header.stamp.isZero()) t.header.stamp = wall(t.header.stamp - ros::Duration(plan.stamp_skew) + shift);
        waitUntil(wall(m.getTime() + shift));
        tf.publish(msg);
      }
    }
    if (in_pass == 0) break;  // nothing playable: do not spin
  }
  ros::WallDuration(0.5).sleep();  // the last messages leave the publisher's queue
  ros::shutdown();
  return clouds == total ? 0 : 1;
}

}  // namespace bench
}  // namespace tools
}  // namespace ret3d
