// Shared by the pipeline rostests (test/rostest) and the command tests of test/ros: a rosconsole appender that keeps
// every log line (to check what a nodelet said), a wait helper, the in-process loading of the real nodelets, and
// PointCloud2 layouts a user may have (Ouster, no intensity, uint8 intensity, big-endian) next to the velodyne one of
// toPointCloud2.
#pragma once

#include <fcntl.h>
#include <nodelet/loader.h>
#include <ros/console.h>
#include <ros/ros.h>
#include <sensor_msgs/PointCloud2.h>
#include <signal.h>
#include <spawn.h>
#include <sys/wait.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstring>
#include <functional>
#include <mutex>
#include <string>
#include <thread>
#include <utility>
#include <vector>

#include "ret3d/core/types.h"

extern char** environ;

namespace ret3d {
namespace test {

class LogCapture : public ros::console::LogAppender {
 public:
  LogCapture() { ros::console::register_appender(this); }
  ~LogCapture() override { ros::console::deregister_appender(this); }
  void log(ros::console::Level, const char* str, const char*, const char*, int) override {
    std::lock_guard<std::mutex> lock(mutex_);
    lines_.emplace_back(str);
  }
  // The first line containing every one of `parts`, or "" when none does.
  std::string find(const std::vector<std::string>& parts) const {
    std::lock_guard<std::mutex> lock(mutex_);
    for (const auto& l : lines_) {
      bool all = true;
      for (const auto& p : parts) all = all && l.find(p) != std::string::npos;
      if (all) return l;
    }
    return "";
  }
  std::string all() const {
    std::lock_guard<std::mutex> lock(mutex_);
    std::string s;
    for (const auto& l : lines_) s += l + "\n";
    return s;
  }

 private:
  mutable std::mutex mutex_;
  std::vector<std::string> lines_;
};

inline sensor_msgs::PointField field(const std::string& name, std::uint32_t offset, std::uint8_t type) {
  sensor_msgs::PointField f;
  f.name = name;
  f.offset = offset;
  f.datatype = type;
  f.count = 1;
  return f;
}

// An Ouster OS1-64 driver cloud (the first 64 * W points of `cloud`): organized 64 x W, point_step 48 with padding,
// x y z float32, intensity float32 in the thousands, t uint32 ns, reflectivity uint16, ring uint8.
inline sensor_msgs::PointCloud2 ousterCloud(const PointCloud& cloud, const std_msgs::Header& header) {
  sensor_msgs::PointCloud2 msg;
  msg.header = header;
  msg.height = 64;
  msg.width = static_cast<std::uint32_t>(cloud.size() / 64);
  msg.fields = {field("x", 0, sensor_msgs::PointField::FLOAT32), field("y", 4, sensor_msgs::PointField::FLOAT32),
                field("z", 8, sensor_msgs::PointField::FLOAT32),
                field("intensity", 16, sensor_msgs::PointField::FLOAT32),
                field("t", 20, sensor_msgs::PointField::UINT32),
                field("reflectivity", 24, sensor_msgs::PointField::UINT16),
                field("ring", 26, sensor_msgs::PointField::UINT8)};
  msg.point_step = 48;
  msg.row_step = msg.point_step * msg.width;
  msg.is_dense = false;
  msg.data.assign(static_cast<std::size_t>(msg.row_step) * msg.height, 0);
  for (std::size_t i = 0; i < static_cast<std::size_t>(msg.width) * msg.height; ++i) {
    std::uint8_t* p = msg.data.data() + i * msg.point_step;
    const Point q = cloud.points[i];
    const float intensity = q.intensity * 3000.0f;
    const std::uint32_t t = static_cast<std::uint32_t>(i % 1024) * 97000u;
    std::memcpy(p + 0, &q.x, 4);
    std::memcpy(p + 4, &q.y, 4);
    std::memcpy(p + 8, &q.z, 4);
    std::memcpy(p + 16, &intensity, 4);
    std::memcpy(p + 20, &t, 4);
    p[26] = static_cast<std::uint8_t>(i / msg.width);
  }
  return msg;
}

// A packed, unorganized cloud of `fields` (point_step bytes a point), each point's bytes written by `write`.
template <typename Write>
sensor_msgs::PointCloud2 packedCloud(const PointCloud& cloud, const std_msgs::Header& header,
                                     std::vector<sensor_msgs::PointField> fields, std::uint32_t point_step,
                                     Write write) {
  sensor_msgs::PointCloud2 msg;
  msg.header = header;
  msg.height = 1;
  msg.width = static_cast<std::uint32_t>(cloud.size());
  msg.fields = std::move(fields);
  msg.point_step = point_step;
  msg.row_step = point_step * msg.width;
  msg.is_dense = true;
  msg.data.resize(msg.row_step);
  for (std::size_t i = 0; i < cloud.size(); ++i) write(cloud.points[i], msg.data.data() + point_step * i);
  return msg;
}

inline std::vector<sensor_msgs::PointField> xyzFields() {
  return {field("x", 0, sensor_msgs::PointField::FLOAT32), field("y", 4, sensor_msgs::PointField::FLOAT32),
          field("z", 8, sensor_msgs::PointField::FLOAT32)};
}

// x, y, z float32 only.
inline sensor_msgs::PointCloud2 xyzCloud(const PointCloud& cloud, const std_msgs::Header& header) {
  return packedCloud(cloud, header, xyzFields(), 12, [](const Point& q, std::uint8_t* p) { std::memcpy(p, &q, 12); });
}

// x, y, z float32 and intensity uint8 (0-255), packed (point_step 13).
inline sensor_msgs::PointCloud2 uint8IntensityCloud(const PointCloud& cloud, const std_msgs::Header& header) {
  auto fields = xyzFields();
  fields.push_back(field("intensity", 12, sensor_msgs::PointField::UINT8));
  return packedCloud(cloud, header, fields, 13, [](const Point& q, std::uint8_t* p) {
    std::memcpy(p, &q, 12);
    p[12] = static_cast<std::uint8_t>(std::clamp(q.intensity, 0.0f, 1.0f) * 255.0f);
  });
}

// x, y, z, intensity float32 in big-endian byte order (is_bigendian set), as a big-endian host's driver sends them.
inline sensor_msgs::PointCloud2 bigEndianCloud(const PointCloud& cloud, const std_msgs::Header& header) {
  auto fields = xyzFields();
  fields.push_back(field("intensity", 12, sensor_msgs::PointField::FLOAT32));
  sensor_msgs::PointCloud2 msg = packedCloud(cloud, header, fields, 16, [](const Point& q, std::uint8_t* p) {
    std::memcpy(p, &q, 16);  // x, y, z, intensity
    if (__BYTE_ORDER__ != __ORDER_BIG_ENDIAN__) {
      for (int k = 0; k < 4; ++k) std::reverse(p + 4 * k, p + 4 * k + 4);
    }
  });
  msg.is_bigendian = 1;
  return msg;
}

// A million points on rings around the sensor (the same every time).
inline PointCloud millionPointCloud() {
  PointCloud big;
  big.points.reserve(1000000);
  for (int i = 0; i < 1000000; ++i) {
    const double a = i * 0.000628, r = 3.0 + (i % 2000) * 0.01;
    big.points.push_back({static_cast<float>(r * std::cos(a)), static_cast<float>(r * std::sin(a)),
                          static_cast<float>(-1.7 + 0.001 * (i % 3000)), 0.3f});
  }
  return big;
}

// What a subscriber saw, by arrival.
template <typename M>
struct Inbox {
  std::mutex mutex;
  std::vector<typename M::ConstPtr> messages;
  ros::Subscriber sub;
  void listen(ros::NodeHandle& nh, const std::string& topic) {
    sub = nh.subscribe<M>(topic, 100, [this](const typename M::ConstPtr& m) {
      std::lock_guard<std::mutex> lock(mutex);
      messages.push_back(m);
    });
  }
  std::size_t size() {
    std::lock_guard<std::mutex> lock(mutex);
    return messages.size();
  }
  std::vector<typename M::ConstPtr> all() {
    std::lock_guard<std::mutex> lock(mutex);
    return messages;
  }
};

// Polls `done` every 10 ms until it holds or `timeout` (s) passes.
inline bool waitFor(const std::function<bool()>& done, double timeout) {
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::duration<double>(timeout);
  while (std::chrono::steady_clock::now() < deadline) {
    if (done()) return true;
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  return done();
}

// Loads a real nodelet of this package into `loader` (pluginlib finds libret3d_nodelets through the devel space).
inline bool loadNodelet(nodelet::Loader& loader, const std::string& name, const std::string& type,
                        const ros::M_string& remappings = {}) {
  return loader.load(name, type, remappings, std::vector<std::string>());
}

// Child processes (roslaunch, Xvfb, rviz, imagemagick) with stdout and stderr appended to `log`.
inline pid_t spawnLogged(const std::vector<std::string>& args, const std::string& log) {
  std::vector<std::string> copy = args;
  std::vector<char*> argv;
  for (auto& a : copy) argv.push_back(a.data());
  argv.push_back(nullptr);
  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  posix_spawn_file_actions_addopen(&actions, 1, log.c_str(), O_WRONLY | O_CREAT | O_APPEND, 0644);
  posix_spawn_file_actions_adddup2(&actions, 1, 2);
  pid_t pid = 0;
  const int rc = posix_spawnp(&pid, argv[0], &actions, nullptr, argv.data(), environ);
  posix_spawn_file_actions_destroy(&actions);
  return rc == 0 ? pid : -1;
}

// Waits up to `timeout` s for the child; returns its exit status, or -1 when it had to be stopped (SIGINT, then
// SIGKILL after 10 s) or died of a signal.
inline int waitLogged(pid_t pid, double timeout) {
  if (pid <= 0) return -2;
  int status = 0;
  if (waitFor([&] { return waitpid(pid, &status, WNOHANG) == pid; }, timeout)) {
    return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  }
  kill(pid, SIGINT);
  if (!waitFor([&] { return waitpid(pid, &status, WNOHANG) == pid; }, 10.0)) {
    kill(pid, SIGKILL);
    waitpid(pid, &status, 0);
  }
  return -1;
}

inline int runLogged(const std::vector<std::string>& args, const std::string& log, double timeout) {
  return waitLogged(spawnLogged(args, log), timeout);
}

}  // namespace test
}  // namespace ret3d
