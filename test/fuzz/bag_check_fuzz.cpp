// Fuzz target: the bag reader of `ret3d convert --check` (ret3d::checkBag, src/ros/kitti_bag.cpp). The first byte
// picks how the input becomes a bag:
//   even: the rest of the input is the bag file itself (rosbag's parser and checkBag on damaged files);
//   odd:  the rest drives a writer that records a well-formed bag of fuzzed messages (clouds of any layout, frame
//         and stamp, transforms with any frames, stamps and values, ground truth, wrong types on known topics,
//         unknown topics; no, bz2 or lz4 compression), so checkBag's own checks are reached.
// checkBag must return a report, or refuse a file it cannot open as a bag with std::runtime_error naming it; for a
// well-formed bag it must always return a report.
#include <fuzzer/FuzzedDataProvider.h>
#include <rosbag/bag.h>
#include <sensor_msgs/PointCloud2.h>
#include <std_msgs/String.h>
#include <tf2_msgs/TFMessage.h>

#include <memory>
#include <stdexcept>

#include "fuzz_util.h"
#include "ret3d/Object3DArray.h"
#include "ret3d/ros/kitti_bag.h"

namespace {

const char* const kFrames[] = {"odom", "base_link", "velodyne", "", "map", "odom"};
const char* const kFieldNames[] = {"x", "y", "z", "intensity", "i", "ring", "time", "t"};
const char* const kTopics[] = {"/points", "/tf", "/tf_static", "/ground_truth/objects", "/other"};

std::string frame(FuzzedDataProvider& in) { return kFrames[in.ConsumeIntegralInRange<int>(0, 5)]; }

ros::Time stamp(FuzzedDataProvider& in) {
  // Mostly near the converter's start time, so transforms and clouds meet; sometimes anywhere.
  if (in.ConsumeBool()) return ros::Time(1.0e9 + in.ConsumeIntegralInRange<int>(0, 20) * 0.05);
  ros::Time t;
  t.sec = in.ConsumeIntegral<std::uint32_t>();
  t.nsec = in.ConsumeIntegralInRange<std::uint32_t>(0, 999999999);
  return t;
}

sensor_msgs::PointCloud2 cloud(FuzzedDataProvider& in) {
  sensor_msgs::PointCloud2 msg;
  msg.header.frame_id = frame(in);
  msg.header.stamp = stamp(in);
  const int n_fields = in.ConsumeIntegralInRange<int>(0, 6);
  for (int k = 0; k < n_fields; ++k) {
    sensor_msgs::PointField f;
    f.name = kFieldNames[in.ConsumeIntegralInRange<int>(0, 7)];
    f.offset = in.ConsumeIntegralInRange<std::uint32_t>(0, 24);
    f.datatype = in.ConsumeIntegralInRange<std::uint8_t>(0, 9);
    f.count = 1;
    msg.fields.push_back(f);
  }
  msg.width = in.ConsumeIntegralInRange<std::uint32_t>(0, 16);
  msg.height = in.ConsumeIntegralInRange<std::uint32_t>(0, 3);
  msg.point_step = in.ConsumeIntegralInRange<std::uint32_t>(0, 32);
  msg.row_step = msg.width * msg.point_step + in.ConsumeIntegralInRange<std::uint32_t>(0, 8);
  msg.is_bigendian = in.ConsumeBool();
  msg.data = in.ConsumeBytes<std::uint8_t>(in.ConsumeIntegralInRange<std::size_t>(0, 1024));
  return msg;
}

tf2_msgs::TFMessage transforms(FuzzedDataProvider& in) {
  tf2_msgs::TFMessage msg;
  const int n = in.ConsumeIntegralInRange<int>(0, 3);
  for (int k = 0; k < n; ++k) {
    geometry_msgs::TransformStamped t;
    t.header.frame_id = frame(in);
    t.child_frame_id = frame(in);
    t.header.stamp = stamp(in);
    t.transform.translation.x = in.ConsumeFloatingPoint<double>();
    t.transform.translation.z = in.ConsumeFloatingPoint<double>();
    t.transform.rotation.w = in.ConsumeBool() ? 1.0 : in.ConsumeFloatingPoint<double>();
    t.transform.rotation.z = in.ConsumeBool() ? 0.0 : in.ConsumeFloatingPoint<double>();
    msg.transforms.push_back(t);
  }
  return msg;
}

ret3d::Object3DArray objects(FuzzedDataProvider& in) {
  ret3d::Object3DArray msg;
  msg.header.frame_id = frame(in);
  msg.header.stamp = stamp(in);
  const int n = in.ConsumeIntegralInRange<int>(0, 3);
  for (int k = 0; k < n; ++k) {
    ret3d::Object3D o;
    o.label = in.ConsumeIntegral<std::uint8_t>();
    o.pose.position.x = in.ConsumeFloatingPoint<double>();
    o.dimensions.x = in.ConsumeFloatingPoint<double>();
    msg.objects.push_back(o);
  }
  return msg;
}

void writeBag(FuzzedDataProvider& in, const std::string& path) {
  rosbag::Bag bag(path, rosbag::bagmode::Write);
  bag.setCompression(static_cast<rosbag::compression::CompressionType>(in.ConsumeIntegralInRange<int>(0, 2)));
  bag.setChunkThreshold(in.ConsumeIntegralInRange<std::uint32_t>(64, 1 << 16));
  for (int k = 0; k < 64 && in.remaining_bytes() > 0; ++k) {
    ros::Time receive(1.0e9 + in.ConsumeIntegralInRange<int>(0, 40) * 0.05);
    switch (in.ConsumeIntegralInRange<int>(0, 5)) {
      case 0:
        bag.write("/points", receive, cloud(in));
        break;
      case 1:
        bag.write("/tf", receive, transforms(in));
        break;
      case 2:
        bag.write("/tf_static", receive, transforms(in));
        break;
      case 3:
        bag.write("/ground_truth/objects", receive, objects(in));
        break;
      case 4: {
        std_msgs::String s;
        s.data = in.ConsumeRandomLengthString(64);
        bag.write(kTopics[in.ConsumeIntegralInRange<int>(0, 4)], receive, s);
        break;
      }
      case 5:
        bag.write("/other", receive, cloud(in));
        break;
    }
  }
  bag.close();
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size < 1) return 0;
  const bool written = data[0] % 2 == 1;
  std::string path;
  std::unique_ptr<ret3d::fuzz::TempFile> file;
  if (written) {
    file = std::make_unique<ret3d::fuzz::TempFile>(".bag", std::string());
    FuzzedDataProvider in(data + 1, size - 1);
    writeBag(in, file->path());
  } else {
    file = std::make_unique<ret3d::fuzz::TempFile>(".bag", data + 1, size - 1);
  }
  try {
    const ret3d::CheckReport report = ret3d::checkBag(file->path(), "odom");
    report.summary();
  } catch (const std::runtime_error& e) {
    if (written) ret3d::fuzz::unexpectedException("checkBag of a well-formed bag", e);
    if (std::string(e.what()).find(file->path()) == std::string::npos)
      ret3d::fuzz::finding(std::string("error without the file name: ") + e.what());
  } catch (const std::exception& e) {
    ret3d::fuzz::unexpectedException("checkBag", e);
  }
  return 0;
}
