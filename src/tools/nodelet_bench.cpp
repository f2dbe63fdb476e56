// The pipeline timed through the real nodelets in one manager (src/tools/nodelet_bench.h).
#include "tools/nodelet_bench.h"

#include <fcntl.h>
#include <netinet/in.h>
#include <signal.h>
#include <sys/prctl.h>
#include <sys/resource.h>
#include <sys/socket.h>
#include <sys/wait.h>
#include <unistd.h>

#include <nodelet/loader.h>
#include <ros/ros.h>
#include <rosbag/bag.h>
#include <rosbag/view.h>
#include <diagnostic_msgs/DiagnosticArray.h>
#include <sensor_msgs/PointCloud2.h>
#include <tf2_msgs/TFMessage.h>
#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <deque>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <iostream>
#include <map>
#include <mutex>
#include <optional>
#include <sstream>
#include <stdexcept>
#include <thread>
#include <utility>

#include "ret3d/DetectionArray.h"
#include "ret3d/Object3DArray.h"
#include "ret3d/core/json_writer.h"
#include "ret3d/core/stats.h"
#include "ret3d/pipeline/stage_layout.h"
#include "ret3d/ros/bag_reader.h"
#include "ret3d/ros/diagnostics.h"
#include "ret3d/ros/params.h"

namespace ret3d {
namespace tools {
namespace {

namespace fs = std::filesystem;

constexpr const char* kPoints = "/points";  // the pipeline's input, as launch/ret3d.launch names it
constexpr const char* kTf = "/tf";
constexpr const char* kTfStatic = "/tf_static";

// What the bag holds for the run, from its index (no cloud is read but the first).
struct BagPlan {
  std::string topic;               // PointCloud2 topic in the bag
  std::size_t clouds = 0;          // clouds to play (at most --max-frames)
  ros::Time start;                 // record time of the first message played (cloud, /tf or /tf_static)
  double duration = 0;             // s of bag time from start to the last cloud played
  double first_cloud = 0;          // s of bag time from start to the first cloud
  double cloud_rate_hz = 0;        // the clouds' own rate
  double stamp_skew = 0;           // header stamps minus record times, when they come from another clock (else 0)
  bool tf = false, tf_static = false;
};

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

// ---- child processes ------------------------------------------------------------------------------------------

// A child process stopped (signal, then SIGKILL after a grace period) and reaped when it goes out of scope.
class ChildProcess {
 public:
  ChildProcess() = default;
  explicit ChildProcess(pid_t pid) : pid_(pid) {}
  ChildProcess(const ChildProcess&) = delete;
  ChildProcess& operator=(const ChildProcess&) = delete;
  ~ChildProcess() { stop(SIGTERM); }

  pid_t pid() const { return pid_; }
  // True once the child has ended (exit status and resource use then available).
  bool ended() {
    if (pid_ <= 0) return true;
    int status = 0;
    if (wait4(pid_, &status, WNOHANG, &usage_) == pid_) {
      pid_ = -1;
      status_ = status;
    }
    return pid_ <= 0;
  }
  void stop(int sig, double grace_s = 5.0) {
    if (ended()) return;
    kill(pid_, sig);
    const auto deadline = std::chrono::steady_clock::now() + std::chrono::duration<double>(grace_s);
    while (!ended() && std::chrono::steady_clock::now() < deadline) std::this_thread::sleep_for(std::chrono::milliseconds(20));
    if (!ended()) {
      kill(pid_, SIGKILL);
      int status = 0;
      wait4(pid_, &status, 0, &usage_);
      pid_ = -1;
    }
  }
  int exitCode() const { return WIFEXITED(status_) ? WEXITSTATUS(status_) : -1; }
  double cpuSeconds() const {
    return static_cast<double>(usage_.ru_utime.tv_sec + usage_.ru_stime.tv_sec) +
           1e-6 * static_cast<double>(usage_.ru_utime.tv_usec + usage_.ru_stime.tv_usec);
  }

 private:
  pid_t pid_ = -1;
  int status_ = 0;
  rusage usage_{};
};

// A TCP port free at the moment (the kernel's choice for port 0).
int freePort() {
  const int s = socket(AF_INET, SOCK_STREAM, 0);
  if (s < 0) throw std::runtime_error(std::string("socket: ") + std::strerror(errno));
  sockaddr_in addr{};
  addr.sin_family = AF_INET;
  addr.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  addr.sin_port = 0;
  socklen_t len = sizeof(addr);
  const bool ok = bind(s, reinterpret_cast<sockaddr*>(&addr), sizeof(addr)) == 0 &&
                  getsockname(s, reinterpret_cast<sockaddr*>(&addr), &len) == 0;
  close(s);
  if (!ok) throw std::runtime_error(std::string("no free TCP port: ") + std::strerror(errno));
  return ntohs(addr.sin_port);
}

// `rosmaster --core -p PORT`, its output discarded (it logs to ROS_LOG_DIR). It ends with this process even when
// this one is killed (PR_SET_PDEATHSIG), so no master outlives a bench stopped by a test's time limit.
pid_t spawnMaster(int port) {
  const std::string port_text = std::to_string(port);
  const pid_t parent = getpid();
  const pid_t pid = fork();
  if (pid < 0) throw std::runtime_error(std::string("fork: ") + std::strerror(errno));
  if (pid == 0) {
    prctl(PR_SET_PDEATHSIG, SIGTERM);
    if (getppid() != parent) _exit(1);
    const int null = open("/dev/null", O_WRONLY);
    dup2(null, STDOUT_FILENO);
    dup2(null, STDERR_FILENO);
    execlp("rosmaster", "rosmaster", "--core", "-p", port_text.c_str(), static_cast<char*>(nullptr));
    _exit(127);
  }
  return pid;
}

// After ros::init: the master (just started) answers, or a runtime_error after 15 s (at once when `master`, the
// process, has ended).
void waitForMaster(ChildProcess* master = nullptr) {
  for (const ros::WallTime deadline = ros::WallTime::now() + ros::WallDuration(15.0); !ros::master::check();) {
    if (master && master->ended())
      throw std::runtime_error(master->exitCode() == 127 ? "rosmaster not found: is ROS on PATH? (`source scripts/env.sh`)"
                                                         : "rosmaster ended at start (exit code " +
                                                               std::to_string(master->exitCode()) + ")");
    if (ros::WallTime::now() > deadline)
      throw std::runtime_error("the ROS master at " + ros::master::getURI() + " did not come up within 15 s");
    ros::WallDuration(0.1).sleep();
  }
}

// ---- the player (a forked child) ------------------------------------------------------------------------------

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

// ---- the manager's side ---------------------------------------------------------------------------------------

// config/ret3d.yaml onto the parameter server, as `rosparam load` with subst_value does in launch/ret3d.launch.
XmlRpc::XmlRpcValue toXmlRpc(const YAML::Node& n) {
  XmlRpc::XmlRpcValue v;
  if (n.IsMap()) {
    v = XmlRpc::XmlRpcValue();
    for (const auto& kv : n) {
      if (kv.second.IsNull()) continue;
      v[kv.first.as<std::string>()] = toXmlRpc(kv.second);
    }
  } else if (n.IsSequence()) {
    v.setSize(static_cast<int>(n.size()));
    for (std::size_t i = 0; i < n.size(); ++i) v[static_cast<int>(i)] = toXmlRpc(n[i]);
  } else {
    bool b;
    int i;
    double d;
    if (n.Tag() == "!") v = n.as<std::string>();  // quoted: a string whatever it looks like
    else if (YAML::convert<bool>::decode(n, b)) v = b;
    else if (YAML::convert<int>::decode(n, i)) v = i;
    else if (YAML::convert<double>::decode(n, d)) v = d;
    else v = n.as<std::string>();
  }
  return v;
}

void loadParams(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw std::runtime_error(path + ": cannot read the nodelets' parameters (--params)");
  std::stringstream ss;
  ss << in.rdbuf();
  std::string text = ss.str();
  const std::string find = "$(find ret3d)";
  for (std::size_t pos = text.find(find); pos != std::string::npos; pos = text.find(find, pos))
    text.replace(pos, find.size(), packagePath());
  YAML::Node root;
  try {
    root = YAML::Load(text);
  } catch (const YAML::Exception& e) {
    throw std::runtime_error(path + ":" + std::to_string(e.mark.line + 1) + ": " + e.msg);
  }
  if (!root.IsMap()) throw std::runtime_error(path + ": a dictionary of nodelet sections expected");
  for (const auto& kv : root) ros::param::set("/" + kv.first.as<std::string>(), toXmlRpc(kv.second));
}

double cpuSecondsOfThisProcess() {
  rusage u{};
  getrusage(RUSAGE_SELF, &u);
  return static_cast<double>(u.ru_utime.tv_sec + u.ru_stime.tv_sec) +
         1e-6 * static_cast<double>(u.ru_utime.tv_usec + u.ru_stime.tv_usec);
}

// Ticks of the whole machine from /proc/stat: {steal, all}. Steal is time the hypervisor gave the virtual CPUs to
// someone else; on a shared virtual machine it explains latencies no code change would. {0, 0} when unreadable.
std::pair<double, double> machineTicks() {
  std::ifstream in("/proc/stat");
  std::string cpu;
  in >> cpu;
  if (cpu != "cpu") return {0, 0};
  double v[8] = {0, 0, 0, 0, 0, 0, 0, 0}, all = 0;  // user nice system idle iowait irq softirq steal
  for (double& x : v) {
    in >> x;
    all += x;
  }
  return in ? std::make_pair(v[7], all) : std::make_pair(0.0, 0.0);
}

struct Usage {
  double wall = 0, cpu = 0, steal_ticks = 0, all_ticks = 0;
  static Usage now() {
    const auto [steal, all] = machineTicks();
    return {ros::WallTime::now().toSec(), cpuSecondsOfThisProcess(), steal, all};
  }
};

// When each cloud (by its stamp) reached the manager (slot 0) and each stage's output (slot k) appeared; and the CPU
// this process used from the first measured cloud to the last output.
class Recorder {
 public:
  Recorder(std::size_t slots, std::size_t warmup) : slots_(slots), warmup_(warmup) {}

  void note(std::size_t slot, const ros::Time& stamp, const ros::Time& receipt) {
    std::lock_guard<std::mutex> lock(mutex_);
    auto& at = arrivals_[stamp.toNSec()];
    if (at.empty()) at.assign(slots_, std::nan(""));
    if (std::isnan(at[slot])) at[slot] = receipt.toSec();
    if (slot == 0 && ++clouds_ == warmup_ + 1) start_ = Usage::now();
    if (slot == 0 && every_ > 0 && clouds_ % every_ == 0) boundaries_.push_back({clouds_, stamp.toNSec()});
    if (slot == 0) last_stamp_ = std::max(last_stamp_, stamp.toNSec());
    if (slot + 1 == slots_ && clouds_ > warmup_) end_ = Usage::now();
  }

  // ---- the soak's windows: bounded bookkeeping, so the manager's own memory does not grow with the run ----
  // Every `every` clouds, the count and the stamp of that cloud are kept for takeBoundaries().
  void markEvery(std::size_t every) {
    std::lock_guard<std::mutex> lock(mutex_);
    every_ = every;
  }
  std::vector<std::pair<std::size_t, std::uint64_t>> takeBoundaries() {
    std::lock_guard<std::mutex> lock(mutex_);
    return std::exchange(boundaries_, {});
  }
  // Clouds seen, and the latest stamp among them (ns).
  std::pair<std::size_t, std::uint64_t> clouds() const {
    std::lock_guard<std::mutex> lock(mutex_);
    return {clouds_, last_stamp_};
  }
  // True when every cloud stamped up to `upto` (ns) has the last stage's output.
  bool answeredUpTo(std::uint64_t upto) const {
    std::lock_guard<std::mutex> lock(mutex_);
    for (auto it = arrivals_.begin(); it != arrivals_.end() && it->first <= upto; ++it)
      if (!std::isnan(it->second[0]) && std::isnan(it->second[slots_ - 1])) return false;
    return true;
  }
  // Removes the clouds stamped up to `upto` (ns) and returns those after the warm-up, as measured() does. An output
  // arriving after its cloud was taken out is ignored later (no cloud of its own).
  std::vector<std::pair<double, std::vector<double>>> drain(std::uint64_t upto) {
    std::lock_guard<std::mutex> lock(mutex_);
    std::vector<std::pair<double, std::vector<double>>> out;
    auto it = arrivals_.begin();
    for (; it != arrivals_.end() && it->first <= upto; ++it) {
      if (std::isnan(it->second[0])) continue;
      if (drained_++ < warmup_) continue;
      out.emplace_back(ros::Time().fromNSec(it->first).toSec(), it->second);
    }
    arrivals_.erase(arrivals_.begin(), it);
    return out;
  }
  // Clouds seen, and how many of them have the last stage's output.
  std::pair<std::size_t, std::size_t> progress() const {
    std::lock_guard<std::mutex> lock(mutex_);
    std::size_t in = 0, out = 0;
    for (const auto& [stamp, at] : arrivals_) {
      in += std::isnan(at[0]) ? 0 : 1;
      out += !std::isnan(at[0]) && !std::isnan(at[slots_ - 1]) ? 1 : 0;
    }
    return {in, out};
  }
  // Per measured cloud (stamp order, warm-up left out): stamp (s) and arrival per slot (NaN: none).
  std::vector<std::pair<double, std::vector<double>>> measured() const {
    std::lock_guard<std::mutex> lock(mutex_);
    std::vector<std::pair<double, std::vector<double>>> out;
    std::size_t seen = 0;
    for (const auto& [stamp, at] : arrivals_) {
      if (std::isnan(at[0])) continue;  // an output without its cloud: the warm-up's, received late
      if (seen++ < warmup_) continue;
      out.emplace_back(ros::Time().fromNSec(stamp).toSec(), at);
    }
    return out;
  }
  // Over the measured window: CPU cores used by this process (CPU seconds per wall second), the window's length (s),
  // and the machine's steal time (percent of all CPU time).
  struct Cpu {
    double cores = 0, seconds = 0, steal_percent = 0;
  };
  Cpu cpu() const {
    std::lock_guard<std::mutex> lock(mutex_);
    const double wall = end_.wall - start_.wall;
    if (wall <= 0) return {};
    const double all = end_.all_ticks - start_.all_ticks;
    return {(end_.cpu - start_.cpu) / wall, wall, all > 0 ? 100.0 * (end_.steal_ticks - start_.steal_ticks) / all : 0.0};
  }

 private:
  mutable std::mutex mutex_;
  std::size_t slots_, warmup_, clouds_ = 0;
  std::map<std::uint64_t, std::vector<double>> arrivals_;
  std::size_t every_ = 0, drained_ = 0;
  std::uint64_t last_stamp_ = 0;
  std::vector<std::pair<std::size_t, std::uint64_t>> boundaries_;  // (clouds seen, stamp) every `every_` clouds
  Usage start_, end_;
};

template <typename M>
ros::Subscriber record(ros::NodeHandle& nh, const std::string& topic, std::size_t slot, Recorder* recorder) {
  const boost::function<void(const ros::MessageEvent<M const>&)> cb = [slot, recorder](
                                                                          const ros::MessageEvent<M const>& e) {
    recorder->note(slot, e.getMessage()->header.stamp, e.getReceiptTime());
  };
  // A deep queue: every message is noted, however late this callback runs (the stages' own queues stay at 1).
  return nh.subscribe<M>(topic, 1000, cb);
}

struct Stage {
  std::string name;      // key in the table and the JSON (as `ret3d bench --data`)
  std::string nodelet;   // node name, as launch/ret3d.launch
  std::string type;      // plugin
  std::string input, output;                  // absolute topics, after the remaps
  std::map<std::string, std::string> remaps;  // relative topic names, from -> to
};

struct Row {
  Row(std::string n, std::string w) : name(std::move(n)), what(std::move(w)) {}
  std::string name, what;
  std::vector<double> ms;
  std::size_t in = 0, out = 0;
  double processing_p50 = -1, processing_p95 = -1;  // the stage's own /diagnostics (< 0: none)
};

void printRow(const Row& r, std::size_t frames) {
  std::ostringstream processing;
  processing << std::fixed << std::setprecision(1);
  if (r.processing_p50 >= 0) processing << r.processing_p50 << " / " << r.processing_p95;
  std::cout << std::left << std::setw(12) << r.name << std::right << std::fixed << std::setprecision(1)
            << std::setw(10) << percentile(r.ms, 50) << std::setw(10) << percentile(r.ms, 95) << std::setw(6)
            << r.out << "/" << std::left << std::setw(6) << (r.in ? r.in : frames) << std::right << std::setw(14)
            << processing.str() << "  " << r.what << "\n";
}

// The stages' own reports on /diagnostics (src/ros/diagnostics.cpp): the last one of each nodelet, and when it came.
class DiagnosticsRecorder {
 public:
  void onMessage(const diagnostic_msgs::DiagnosticArray::ConstPtr& msg) {
    const double now = ros::WallTime::now().toSec();
    std::lock_guard<std::mutex> lock(mutex_);
    for (const diagnostic_msgs::DiagnosticStatus& s : msg->status) {
      std::string nodelet = s.name.substr(0, s.name.find(':'));  // "/ret3d_detector: ..." -> "ret3d_detector"
      if (!nodelet.empty() && nodelet.front() == '/') nodelet.erase(0, 1);
      auto& last = last_[nodelet];
      last.first = now;
      for (const diagnostic_msgs::KeyValue& kv : s.values) last.second[kv.key] = kv.value;
    }
  }
  // True when every one of `nodelets` has reported after wall time `since`.
  bool reportedSince(const std::vector<std::string>& nodelets, double since) const {
    std::lock_guard<std::mutex> lock(mutex_);
    for (const std::string& n : nodelets) {
      const auto it = last_.find(n);
      if (it == last_.end() || it->second.first <= since) return false;
    }
    return true;
  }
  // The value of `key` in the nodelet's last report, or -1.
  double value(const std::string& nodelet, const std::string& key) const {
    std::lock_guard<std::mutex> lock(mutex_);
    const auto it = last_.find(nodelet);
    if (it == last_.end() || !it->second.second.count(key)) return -1;
    try {
      return std::stod(it->second.second.at(key));
    } catch (const std::exception&) {
      return -1;
    }
  }

 private:
  mutable std::mutex mutex_;
  std::map<std::string, std::pair<double, std::map<std::string, std::string>>> last_;
};

// ---- the soak (--loop-frames) ---------------------------------------------------------------------------------

// What /proc says about this process, the one hosting the nodelets.
struct ProcessSample {
  double wall_s = 0, cpu_s = 0;  // wall clock and CPU seconds used so far
  double rss_mb = 0;             // VmRSS
  int fds = 0, threads = 0;      // entries of /proc/self/fd, Threads
  double machine_load = 0;       // the machine's 1-minute load average: what the latencies of a shared host follow
};

ProcessSample sampleThisProcess() {
  ProcessSample p;
  p.wall_s = ros::WallTime::now().toSec();
  p.cpu_s = cpuSecondsOfThisProcess();
  std::ifstream status("/proc/self/status");
  for (std::string line; std::getline(status, line);) {
    std::istringstream in(line);
    std::string key;
    in >> key;
    if (key == "VmRSS:") {
      double kb = 0;
      in >> kb;
      p.rss_mb = kb / 1024.0;
    } else if (key == "Threads:") {
      in >> p.threads;
    }
  }
  std::ifstream("/proc/loadavg") >> p.machine_load;
  std::error_code ec;
  for (fs::directory_iterator it("/proc/self/fd", ec), end; !ec && it != end; it.increment(ec)) ++p.fds;
  return p;
}

struct SoakWindow {
  std::size_t frame = 0;  // clouds played when the sample was taken
  ProcessSample process;
  std::vector<double> end_to_end_ms, base_ms;  // per answered cloud since the previous sample (after the warm-up)
  std::size_t measured = 0, answered = 0;      // clouds after the warm-up in the window, those with an output
  double cpu_cores = 0;                        // CPU seconds per wall second since the previous sample
};

// Samples the process when every `every`-th cloud arrives, and takes that window's clouds out of the recorder once
// they are answered (or `settle_s` after the sample: a skipped cloud never is), so the bench holds at most a few
// windows of clouds however long it runs. Prints a line per window.
class Soak {
 public:
  Soak(Recorder* recorder, std::size_t every, double settle_s) : recorder_(recorder), settle_s_(settle_s) {
    recorder_->markEvery(every);
  }
  void begin() {
    SoakWindow w;
    w.process = sampleThisProcess();
    windows_.push_back(std::move(w));
    print(windows_.back());
  }
  // The player has ended: the clouds after the last sample form a last, shorter window.
  void end() {
    poll();
    const auto [clouds, stamp] = recorder_->clouds();
    const std::size_t last = pending_.empty() ? windows_.back().frame : pending_.back().window.frame;
    if (clouds > last) add(clouds, stamp);
  }
  void poll() {
    for (const auto& [clouds, stamp] : recorder_->takeBoundaries()) add(clouds, stamp);
    const double now = ros::WallTime::now().toSec();
    while (!pending_.empty() &&
           (recorder_->answeredUpTo(pending_.front().upto) || now - pending_.front().window.process.wall_s > settle_s_)) {
      Pending& p = pending_.front();
      for (const auto& [stamp, at] : recorder_->drain(p.upto)) {
        ++p.window.measured;
        if (std::isnan(at.back())) continue;
        ++p.window.answered;
        p.window.end_to_end_ms.push_back(1e3 * (at.back() - stamp));
        if (!std::isnan(at[1])) p.window.base_ms.push_back(1e3 * (at[1] - at[0]));
      }
      const ProcessSample& before = windows_.back().process;
      const double wall = p.window.process.wall_s - before.wall_s;
      p.window.cpu_cores = wall > 0 ? (p.window.process.cpu_s - before.cpu_s) / wall : 0;
      windows_.push_back(std::move(p.window));
      pending_.pop_front();
      print(windows_.back());
    }
  }
  bool idle() const { return pending_.empty(); }
  const std::vector<SoakWindow>& windows() const { return windows_; }

 private:
  struct Pending {
    SoakWindow window;
    std::uint64_t upto;  // the stamp of the window's last cloud (ns)
  };
  void add(std::size_t clouds, std::uint64_t stamp) {
    Pending p{{}, stamp};
    p.window.frame = clouds;
    p.window.process = sampleThisProcess();
    pending_.push_back(std::move(p));
  }
  static void print(const SoakWindow& w) {
    std::cout << std::fixed << std::setprecision(1) << "soak: frame " << std::setw(6) << w.frame << "  RSS "
              << std::setw(7) << w.process.rss_mb << " MB  fds " << std::setw(3) << w.process.fds << "  threads "
              << std::setw(3) << w.process.threads;
    if (w.frame > 0)
      std::cout << "  end-to-end p50/p95/max " << percentile(w.end_to_end_ms, 50) << " / "
                << percentile(w.end_to_end_ms, 95) << " / "
                << (w.end_to_end_ms.empty() ? 0.0 : *std::max_element(w.end_to_end_ms.begin(), w.end_to_end_ms.end()))
                << " ms  detector p50/p95 " << percentile(w.base_ms, 50) << " / " << percentile(w.base_ms, 95)
                << " ms  answered " << w.answered << "/" << w.measured << std::setprecision(2) << "  CPU "
                << w.cpu_cores << " cores  machine load " << w.process.machine_load;
    std::cout << std::endl;
  }

  Recorder* recorder_;
  double settle_s_;
  std::deque<Pending> pending_;
  std::vector<SoakWindow> windows_;  // windows_[0]: the sample before the first cloud
};

// The acceptance checks over the windows, printed, and the JSON and the table for the plot (scripts/soak.sh) written.
// The reference is frame K = 1000 (less on a run shorter than 2000 frames: half the run, in whole windows):
// resident memory from frame K to the end grows by less than 5 %; the descriptor count at the end equals frame K's;
// the end-to-end p95 of the last K frames is at most 10 % above that of the first K.
void reportSoak(const std::vector<SoakWindow>& windows, const NodeletBenchOptions& o, double rate_hz,
                const std::string& last_output) {
  const std::size_t frames = windows.back().frame, every = static_cast<std::size_t>(o.soak_every);
  const std::size_t k = std::min<std::size_t>(1000, frames / 2 / every * every);
  const SoakWindow* ref = nullptr;
  // End-to-end latencies of the windows within the first and the last K frames (with a partial last window, the
  // windows starting at or after frame `frames - K`).
  std::vector<double> first, last;
  std::size_t measured = 0, answered = 0;
  for (const SoakWindow& w : windows) {
    if (w.frame == k) ref = &w;
    if (w.frame > 0 && w.frame <= k) first.insert(first.end(), w.end_to_end_ms.begin(), w.end_to_end_ms.end());
    if (w.frame > k && w.frame >= frames - k + every) last.insert(last.end(), w.end_to_end_ms.begin(), w.end_to_end_ms.end());
    measured += w.measured, answered += w.answered;
  }
  const SoakWindow& end = windows.back();
  const bool checks = ref != nullptr && k > 0;
  const double rss_growth = checks ? 100.0 * (end.process.rss_mb - ref->process.rss_mb) / ref->process.rss_mb : 0;
  const double p95_first = percentile(first, 95), p95_last = percentile(last, 95);
  const double p95_change = p95_first > 0 ? 100.0 * (p95_last - p95_first) / p95_first : 0;
  const bool rss_ok = checks && rss_growth < 5.0, fds_ok = checks && end.process.fds == ref->process.fds;
  const bool p95_ok = checks && !first.empty() && !last.empty() && p95_change <= 10.0;
  int min_fds = end.process.fds, max_fds = end.process.fds;
  double max_rss = 0;
  for (const SoakWindow& w : windows)
    if (w.frame > 0) {
      min_fds = std::min(min_fds, w.process.fds), max_fds = std::max(max_fds, w.process.fds);
      max_rss = std::max(max_rss, w.process.rss_mb);
    }

  std::cout << std::fixed << std::setprecision(1) << "soak: " << frames << " frames at " << rate_hz << " Hz, "
            << answered << " of " << measured << " measured clouds answered on " << last_output << " ("
            << measured - answered << " skipped by the latest-frame policy or late)";
  if (o.load > 0) std::cout << ", " << o.load << " cores kept busy (--load)";
  std::cout << "\n";
  if (!checks) {
    std::cout << "soak: too short for the checks (they need two windows of --soak-every " << every
              << " frames before and after a reference frame)\n";
  } else {
    auto verdict = [](bool ok) { return ok ? "PASS" : "FAIL"; };
    std::cout << std::setprecision(1) << "soak check: resident memory frame " << k << " -> " << frames << ": "
              << ref->process.rss_mb << " -> " << end.process.rss_mb << " MB (" << std::showpos << rss_growth
              << std::noshowpos << " %, limit < +5 %; peak " << max_rss << " MB)  " << verdict(rss_ok) << "\n"
              << "soak check: open file descriptors frame " << k << " -> " << frames << ": " << ref->process.fds
              << " -> " << end.process.fds << " (range " << min_fds << "-" << max_fds << " over the run)  "
              << verdict(fds_ok) << "\n"
              << "soak check: end-to-end p95 first " << k << " frames " << p95_first << " ms, last " << k
              << " frames " << p95_last << " ms (" << std::showpos << p95_change << std::noshowpos
              << " %, limit +10 %)  " << verdict(p95_ok) << "\n"
              << "soak: " << (rss_ok && fds_ok && p95_ok ? "all checks pass" : "CHECKS FAILED") << "\n";
  }

  if (o.json.empty()) return;
  JsonWriter json({/*decimals=*/3});
  json.field("frames", frames)
      .field("every", every)
      .field("rate_hz", rate_hz)
      .field("load", o.load)
      .field("warmup", o.warmup)
      .field("measured", measured)
      .field("answered", answered)
      .beginArray("samples");
  std::ostringstream table;
  table << "# frame\twall_s\trss_mb\tfds\tthreads\tcpu_cores\te2e_p50_ms\te2e_p95_ms\te2e_max_ms\tdetector_p50_ms\t"
           "detector_p95_ms\tanswered\tmeasured\tmachine_load\n"
        << std::fixed << std::setprecision(3);
  for (std::size_t i = 0; i < windows.size(); ++i) {
    const SoakWindow& w = windows[i];
    const double max = w.end_to_end_ms.empty() ? 0.0 : *std::max_element(w.end_to_end_ms.begin(), w.end_to_end_ms.end());
    const double t = w.process.wall_s - windows.front().process.wall_s;
    json.beginObject()
        .field("frame", w.frame)
        .field("wall_s", t)
        .field("rss_mb", w.process.rss_mb)
        .field("fds", w.process.fds)
        .field("threads", w.process.threads)
        .field("machine_load", w.process.machine_load);
    if (w.frame > 0)
      json.field("cpu_cores", w.cpu_cores)
          .field("end_to_end_p50_ms", percentile(w.end_to_end_ms, 50))
          .field("end_to_end_p95_ms", percentile(w.end_to_end_ms, 95))
          .field("end_to_end_max_ms", max)
          .field("detector_p50_ms", percentile(w.base_ms, 50))
          .field("detector_p95_ms", percentile(w.base_ms, 95))
          .field("answered", w.answered)
          .field("measured", w.measured);
    json.endObject();
    if (w.frame > 0)
      table << w.frame << "\t" << t << "\t" << w.process.rss_mb << "\t" << w.process.fds << "\t" << w.process.threads
            << "\t" << w.cpu_cores << "\t" << percentile(w.end_to_end_ms, 50) << "\t"
            << percentile(w.end_to_end_ms, 95) << "\t" << max << "\t" << percentile(w.base_ms, 50) << "\t"
            << percentile(w.base_ms, 95) << "\t" << w.answered << "\t" << w.measured << "\t"
            << w.process.machine_load << "\n";
  }
  json.endArray();
  if (checks)
    json.beginObject("checks")
        .field("reference_frame", k)
        .field("rss_reference_mb", ref->process.rss_mb)
        .field("rss_end_mb", end.process.rss_mb)
        .field("rss_growth_percent", rss_growth)
        .field("fds_reference", ref->process.fds)
        .field("fds_end", end.process.fds)
        .field("p95_first_ms", p95_first)
        .field("p95_last_ms", p95_last)
        .field("p95_change_percent", p95_change)
        .field("rss_ok", rss_ok)
        .field("fds_ok", fds_ok)
        .field("p95_ok", p95_ok)
        .field("passed", rss_ok && fds_ok && p95_ok)
        .endObject();
  json.save(o.json);
  const std::string tsv = fs::path(o.json).replace_extension(".tsv").string();
  std::ofstream(tsv) << table.str();
  std::cout << "bench: wrote " << o.json << " and " << tsv << "\n";
}


void checkOptions(const NodeletBenchOptions& o) {
  if (o.stages.empty() || o.stages.front() != "base")
    throw std::runtime_error("--stages must start with base: the nodelets are fed point clouds");
  if (o.rate <= 0) throw std::runtime_error("--rate must be > 0, not " + std::to_string(o.rate));
  if (o.loop_frames < 0) throw std::runtime_error("--loop-frames must be >= 0, not " + std::to_string(o.loop_frames));
  if (o.soak_every <= 0) throw std::runtime_error("--soak-every must be > 0, not " + std::to_string(o.soak_every));
  if (o.load < 0) throw std::runtime_error("--load must be >= 0, not " + std::to_string(o.load));
}

bool hasStage(const std::vector<Stage>& stages, const std::string& name) {
  return std::any_of(stages.begin(), stages.end(), [&](const Stage& s) { return s.name == name; });
}

// The nodelets of --stages in pipeline order, as launch/ret3d.launch loads them (the one stage table,
// pipeline/stage_layout.h) with the stages after the last one left out; InterRM brings the tracker it reads from.
// The markers are not a stage here (loadNodelets adds them).
std::vector<Stage> pipelineStages(const NodeletBenchOptions& o) {
  auto has = [&](const std::string& s) { return std::find(o.stages.begin(), o.stages.end(), s) != o.stages.end(); };
  std::map<std::string, bool> switches;
  for (const pipeline::StageLayout& s : pipeline::pipelineLayout())
    if (s.off == pipeline::WhenOff::Bridged) switches[s.switch_arg] = has(s.offline);
  std::vector<Stage> stages;
  for (const pipeline::NodeletLoad& n : pipeline::nodeletsToLoad(switches)) {
    const pipeline::StageLayout& s = *n.stage;
    if (s.offline.empty() || !(has(s.offline) || (s.offline == "track" && has("inter")))) continue;
    stages.push_back({s.offline, s.node, s.nodelet, "/" + n.input(), "/" + s.output, n.remaps});
  }
  return stages;
}

// The write end of the pipe that starts the player.
struct PipeEnd {
  int fd;
  ~PipeEnd() { close(fd); }
};

// Forks the bag player; it starts playing when a byte arrives on *go_fd. Call before this process starts any ROS
// thread.
pid_t forkPlayer(const NodeletBenchOptions& o, const BagPlan& plan, int* go_fd) {
  int go[2];
  if (pipe(go) != 0) throw std::runtime_error(std::string("pipe: ") + std::strerror(errno));
  std::cout.flush();
  std::cerr.flush();
  const pid_t player_pid = fork();
  if (player_pid < 0) throw std::runtime_error(std::string("fork: ") + std::strerror(errno));
  if (player_pid == 0) {
    prctl(PR_SET_PDEATHSIG, SIGTERM);  // a killed bench takes its player along
    close(go[1]);
    int rc = 1;
    try {
      rc = playBag(o, plan, go[0]);
    } catch (const std::exception& e) {
      std::cerr << "bench player: " << e.what() << std::endl;
    }
    _exit(rc);
  }
  close(go[0]);
  *go_fd = go[1];
  return player_pid;
}

// The nodelets' parameters: the package's YAML, then what the options override.
void setNodeletParams(const NodeletBenchOptions& o, const std::string& params) {
  loadParams(params);
  ros::param::set("/ret3d_detector/model_path", o.detector_model);
  ros::param::set("/ret3d_detector/config", o.detector_config);
  ros::param::set("/ret3d_detector/threads", o.threads);
  if (o.score_threshold >= 0) ros::param::set("/ret3d_detector/score_threshold", o.score_threshold);
  if (!o.grid_extent.empty()) ros::param::set("/ret3d_detector/grid_extent", o.grid_extent);
  ros::param::set("/ret3d_intra/model_path", o.intra_model);
  ros::param::set("/ret3d_intra/threads", o.threads);
  if (!o.tracker_config.empty()) ros::param::set("/ret3d_tracker/tracker_config", o.tracker_config);
  ros::param::set("/ret3d_inter/model_path", o.inter_model);
  ros::param::set("/ret3d_inter/threads", o.threads);
  ros::param::set("/ret3d_inter/passthrough", false);
}

void loadNodelets(nodelet::Loader& loader, const std::vector<Stage>& stages, const NodeletBenchOptions& o) {
  std::cout << "bench: loading the nodelets into this process (the manager, " << o.manager_threads
            << " callback threads):";
  std::vector<Stage> load = stages;
  // The markers read InterRM's objects, as the launch file loads them.
  const auto& layout = pipeline::pipelineLayout();
  const auto markers = std::find_if(layout.begin(), layout.end(), [](const auto& s) { return s.offline.empty(); });
  if (o.markers && hasStage(stages, "inter")) load.push_back({"", markers->node, markers->nodelet, "", "", {}});
  for (const Stage& s : load) std::cout << " " << s.type;
  std::cout << std::endl;
  for (const Stage& s : load) {
    ros::M_string remap;
    // A stage left out is bridged as launch/ret3d.launch bridges it (intra:=false: the tracker reads detections).
    for (const auto& [from, to] : s.remaps) remap["/" + from] = "/" + to;
    if (!loader.load("/" + s.nodelet, s.type, remap, {}))
      throw std::runtime_error("nodelet " + s.nodelet + " (" + s.type + ") did not start; see the message above");
  }
}

// Starts the player and waits until it has ended and the pipeline has answered (or --tail has passed); a soak
// samples this process meanwhile.
void playAndWait(const NodeletBenchOptions& o, const BagPlan& plan, ChildProcess& player, int go_fd,
                 Recorder& recorder, std::optional<Soak>& soak_log) {
  const bool soak = soak_log.has_value();
  std::cout << "bench: playing " << plan.clouds << " clouds of " << o.bag << " " << plan.topic << " at "
            << std::setprecision(1) << std::fixed << plan.cloud_rate_hz * o.rate << " Hz"
            << (o.rate != 1.0 ? " (--rate " + std::to_string(o.rate) + ")" : "") << " on " << kPoints
            << " from a player process, stamps moved to now" << (plan.tf ? ", with /tf" : ", no /tf in the bag")
            << (plan.tf_static ? " and /tf_static" : "") << "; " << o.warmup << " warm-up frames left out\n"
            << std::flush;
  if (soak)
    std::cout << "bench: soak: the bag looped for " << o.loop_frames << " clouds; this process (pid " << getpid()
              << ") sampled every " << o.soak_every << " clouds" << std::endl;
  // The other work starts with the replay, after the nodelets have loaded and warmed up.
  std::optional<BusyLoad> busy;
  if (o.load > 0) {
    busy.emplace(o.load);
    std::cout << "bench: " << o.load << " busy process" << (o.load > 1 ? "es" : "") << " spinning (--load) during "
              << "the replay" << std::endl;
  }
  if (soak) soak_log->begin();
  if (write(go_fd, "g", 1) != 1) throw std::runtime_error("the player process is gone");
  const double played_s = (soak ? static_cast<double>(o.loop_frames) / std::max(1e-9, plan.cloud_rate_hz)
                                : plan.duration) / o.rate;
  const ros::WallTime deadline = ros::WallTime::now() + ros::WallDuration(played_s + 30.0 + o.tail);
  ros::WallTime played;
  bool player_done = false;
  while (ros::ok()) {
    const ros::WallTime now = ros::WallTime::now();
    if (!player_done && player.ended()) {
      player_done = true;
      played = now;
      if (player.exitCode() != 0)
        throw std::runtime_error("the player process failed (exit code " + std::to_string(player.exitCode()) +
                                 "); see its message above");
      if (soak) soak_log->end();
    }
    if (soak) {
      soak_log->poll();
      if (player_done && soak_log->idle()) break;
    } else if (player_done) {
      const auto [in, out] = recorder.progress();
      if (in == out || (now - played).toSec() > o.tail) break;
    }
    if (now > deadline) {
      std::cout << "bench: the run took longer than the bag (+30 s); stopping\n";
      break;
    }
    ros::WallDuration(0.02).sleep();
  }
  if (!ros::ok()) throw std::runtime_error("interrupted");
}

// What a run measured: per-cloud times of the input, each stage and end to end, after the warm-up.
struct Measurement {
  explicit Measurement(const std::string& last_output) : end_to_end{"end_to_end", "  stamp to " + last_output} {}
  Row input{"input", "  stamp to cloud in the manager (player, transport)"};
  std::vector<Row> rows;
  Row end_to_end;
  std::size_t frames = 0, frames_out = 0;
  Recorder::Cpu cpu;
  double player_cpu = 0;
  std::vector<SoakWindow> soak_windows;
};

void tabulate(const Recorder& recorder, const DiagnosticsRecorder& diagnostics, const std::vector<Stage>& stages,
              Measurement* m) {
  const auto measured = recorder.measured();
  m->frames = measured.size();
  for (std::size_t k = 0; k < stages.size(); ++k) {
    m->rows.emplace_back(stages[k].name,
                         "  " + stages[k].input + " to " + stages[k].output + " (" + stages[k].type + ")");
    m->rows.back().processing_p50 = diagnostics.value(stages[k].nodelet, "processing p50 (ms)");
    m->rows.back().processing_p95 = diagnostics.value(stages[k].nodelet, "processing p95 (ms)");
  }
  for (const auto& [stamp, at] : measured) {
    m->input.ms.push_back(1e3 * (at[0] - stamp));
    for (std::size_t k = 0; k < stages.size(); ++k) {
      m->rows[k].in += std::isnan(at[k]) ? 0 : 1;
      if (!std::isnan(at[k]) && !std::isnan(at[k + 1])) m->rows[k].ms.push_back(1e3 * (at[k + 1] - at[k]));
      m->rows[k].out += std::isnan(at[k + 1]) ? 0 : 1;
    }
    if (!std::isnan(at.back())) {
      m->end_to_end.ms.push_back(1e3 * (at.back() - stamp));
      ++m->frames_out;
    }
  }
  m->input.in = m->input.out = m->frames;
  m->end_to_end.in = m->frames, m->end_to_end.out = m->frames_out;
  m->cpu = recorder.cpu();
}

// Loads the nodelets into this process, plays the bag through them and records every stage's outputs.
Measurement measure(const NodeletBenchOptions& o, const std::vector<Stage>& stages, const BagPlan& plan,
                    const std::string& params, ChildProcess& player, int go_fd) {
  Measurement m(stages.back().output);
  ros::NodeHandle nh, private_nh("~");
  setNodeletParams(o, params);
  private_nh.setParam("num_worker_threads", o.manager_threads);
  nodelet::Loader loader(private_nh);
  loadNodelets(loader, stages, o);

  Recorder recorder(stages.size() + 1, static_cast<std::size_t>(std::max(0, o.warmup)));
  std::vector<ros::Subscriber> subscribers;
  subscribers.push_back(record<sensor_msgs::PointCloud2>(nh, kPoints, 0, &recorder));
  for (std::size_t k = 0; k < stages.size(); ++k) {
    if (stages[k].output == "/objects")
      subscribers.push_back(record<ret3d::Object3DArray>(nh, stages[k].output, k + 1, &recorder));
    else
      subscribers.push_back(record<ret3d::DetectionArray>(nh, stages[k].output, k + 1, &recorder));
  }
  DiagnosticsRecorder diagnostics;
  subscribers.push_back(nh.subscribe("/diagnostics", 100, &DiagnosticsRecorder::onMessage, &diagnostics));
  ros::AsyncSpinner spinner(2);
  spinner.start();
  const bool soak = o.loop_frames > 0;
  std::optional<Soak> soak_log;
  if (soak) soak_log.emplace(&recorder, static_cast<std::size_t>(o.soak_every), std::max(2.0, o.tail));
  playAndWait(o, plan, player, go_fd, recorder, soak_log);
  // The nodelets report once a second: one more report of each covers the last frames.
  std::vector<std::string> nodelets;
  for (const Stage& s : stages) nodelets.push_back(s.nodelet);
  const double ended = ros::WallTime::now().toSec();
  for (int i = 0; i < 150 && ros::ok() && !soak && !diagnostics.reportedSince(nodelets, ended); ++i)
    ros::WallDuration(0.01).sleep();
  if (soak) m.soak_windows = soak_log->windows();
  spinner.stop();
  subscribers.clear();
  loader.clear();
  m.player_cpu = player.cpuSeconds();
  tabulate(recorder, diagnostics, stages, &m);
  return m;
}

void printTable(const Measurement& m, const std::vector<Stage>& stages, unsigned cores) {
  const std::size_t dropped = m.frames - m.frames_out;
  std::cout << std::left << std::setw(12) << "stage" << std::right << std::setw(10) << "p50 ms" << std::setw(10)
            << "p95 ms" << std::setw(13) << "out/in" << std::setw(16) << "processing ms" << "\n";
  printRow(m.input, m.frames);
  for (const Row& r : m.rows) printRow(r, m.frames);
  printRow(m.end_to_end, m.frames);
  std::cout << "(p50 / p95 per cloud after the warm-up: from the arrival of a stage's input to that of its output, "
               "waiting included; processing p50 / p95: the stage's own /diagnostics over its last 200 frames)\n";
  std::cout << std::setprecision(1) << "frames: " << m.frames << " measured, " << m.frames_out << " with "
            << stages.back().output << ", " << dropped << " dropped ("
            << 100.0 * static_cast<double>(dropped) / std::max<std::size_t>(1, m.frames) << " %)\n"
            << std::setprecision(2) << "CPU: " << m.cpu.cores << " cores of " << cores << " (" << std::setprecision(0)
            << 100.0 * m.cpu.cores / cores << " %) used by the manager process over the " << std::setprecision(1)
            << m.cpu.seconds << " s measured; the player used " << m.player_cpu << " s of CPU in all\n"
            << "machine: " << m.cpu.steal_percent
            << " % of CPU time stolen by the hypervisor meanwhile (/proc/stat steal; above a few percent the timings "
               "say more about the host than about the pipeline)\n";
}

void writeBenchJson(const NodeletBenchOptions& o, const BagPlan& plan, const Measurement& m, unsigned cores) {
  JsonWriter json({/*decimals=*/3});
  auto add = [&](const Row& r) {
    json.beginObject(r.name)
        .field("median_ms", percentile(r.ms, 50))
        .field("p95_ms", percentile(r.ms, 95))
        .field("frames_out", r.out);
    if (r.processing_p50 >= 0)
      json.field("processing_median_ms", r.processing_p50).field("processing_p95_ms", r.processing_p95);
    json.endObject();
  };
  add(m.input);
  for (const Row& r : m.rows) add(r);
  add(m.end_to_end);
  json.field("frames", m.frames)
      .field("frames_out", m.frames_out)
      .field("dropped", m.frames - m.frames_out)
      .field("warmup", o.warmup)
      .field("input_rate_hz", plan.cloud_rate_hz * o.rate)
      .field("cpu_cores", m.cpu.cores)
      .field("cpu_percent", 100.0 * m.cpu.cores / cores)
      .field("steal_percent", m.cpu.steal_percent)
      .field("cores", cores)
      .field("threads", o.threads);
  json.save(o.json);
  std::cout << "bench: wrote " << o.json << "\n";
}

}  // namespace

BusyLoad::BusyLoad(int processes) {
  const pid_t parent = getpid();
  for (int i = 0; i < processes; ++i) {
    const pid_t pid = fork();
    if (pid < 0) {
      const std::string error = std::strerror(errno);
      for (const int started : pids_) kill(started, SIGKILL), waitpid(started, nullptr, 0);
      throw std::runtime_error("--load: fork: " + error);
    }
    if (pid == 0) {
      // Only async-signal-safe calls here: the parent may have threads holding locks.
      prctl(PR_SET_PDEATHSIG, SIGKILL);
      if (getppid() != parent) _exit(0);
      for (volatile std::uint64_t spin = 0;; spin = spin + 1) {
      }
    }
    pids_.push_back(pid);
  }
}

BusyLoad::~BusyLoad() {
  for (const int pid : pids_) kill(pid, SIGKILL);
  for (const int pid : pids_) waitpid(pid, nullptr, 0);
  pids_.clear();
}

int runNodeletBench(const NodeletBenchOptions& o, NodeletBenchResult* result) {
  checkOptions(o);
  const std::vector<Stage> stages = pipelineStages(o);
  const std::string params = o.params.empty() ? packagePath() + "/" + kNodeletParams : o.params;
  if (packagePath().empty() && (o.params.empty() || o.tracker_config.empty()))
    throw std::runtime_error("the ret3d package is not on ROS_PACKAGE_PATH (`source scripts/env.sh`), so its "
                             "config/ret3d.yaml cannot be found; or give --params FILE");
  if (!std::getenv("OMP_WAIT_POLICY"))
    std::cout << "bench: OMP_WAIT_POLICY is not set: libtorch's waiting threads spin and slow every other thread on "
                 "busy cores (`source scripts/env.sh` sets PASSIVE, as the launch files do)\n";

  const BagPlan plan = scanBag(o);

  // A private master: the run neither disturbs a ROS system on this machine (its /points, /tf, /objects) nor is
  // disturbed by one (its /use_sim_time would make the stamps sim time).
  const int port = freePort();
  const std::string master_uri = "http://localhost:" + std::to_string(port) + "/";
  ChildProcess master(spawnMaster(port));
  setenv("ROS_MASTER_URI", master_uri.c_str(), 1);
  std::cout << "bench: private ROS master at " << master_uri << " (rosmaster --core, stopped at the end)\n";

  int go_write = -1;
  ChildProcess player(forkPlayer(o, plan, &go_write));
  const PipeEnd go_fd{go_write};

  ros::M_string no_remappings;
  ros::init(no_remappings, "ret3d_bench");
  waitForMaster(&master);
  // The nodelets' INFO lines (listening on ..., warmed up) would bury the table; warnings and errors still show.
  if (ros::console::set_logger_level("ros", ros::console::levels::Warn)) ros::console::notifyLoggerLevelsChanged();

  const Measurement m = measure(o, stages, plan, params, player, go_fd.fd);
  ros::shutdown();
  master.stop(SIGINT);
  if (o.loop_frames > 0) {
    reportSoak(m.soak_windows, o, plan.cloud_rate_hz * o.rate, stages.back().output);
    return 0;
  }

  const unsigned cores = std::max(1u, std::thread::hardware_concurrency());
  if (result) {
    result->base_p50 = percentile(m.rows.front().ms, 50), result->base_p95 = percentile(m.rows.front().ms, 95);
    result->base_processing_p50 = m.rows.front().processing_p50;
    result->base_processing_p95 = m.rows.front().processing_p95;
    result->end_to_end_p50 = percentile(m.end_to_end.ms, 50);
    result->end_to_end_p95 = percentile(m.end_to_end.ms, 95);
    result->frames = m.frames, result->dropped = m.frames - m.frames_out;
  }
  printTable(m, stages, cores);
  if (!o.json.empty()) writeBenchJson(o, plan, m, cores);
  return 0;
}

}  // namespace tools
}  // namespace ret3d
