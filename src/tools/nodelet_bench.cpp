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
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <iostream>
#include <map>
#include <mutex>
#include <sstream>
#include <stdexcept>
#include <thread>

#include "ret3d/DetectionArray.h"
#include "ret3d/Object3DArray.h"
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
  double cloud_rate_hz = 0;        // the clouds' own rate
  double stamp_skew = 0;           // header stamps minus record times, when they come from another clock (else 0)
  bool tf = false, tf_static = false;
};

BagPlan scanBag(const NodeletBenchOptions& o) {
  if (!fs::is_regular_file(o.bag)) throw std::runtime_error(o.bag + ": no such file");
  BagPlan plan;
  try {
    rosbag::Bag bag(o.bag, rosbag::bagmode::Read);
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
        const auto msg = m.instantiate<sensor_msgs::PointCloud2>();
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
  rosbag::Bag bag(o.bag, rosbag::bagmode::Read);
  std::vector<std::string> topics = {plan.topic};
  if (plan.tf) topics.push_back(kTf);
  if (plan.tf_static) topics.push_back(kTfStatic);
  rosbag::View view(bag, rosbag::TopicQuery(topics));
  std::size_t clouds = 0;
  for (const rosbag::MessageInstance& m : view) {
    if (!ros::ok()) break;
    if (m.getTopic() == plan.topic) {
      if (clouds >= plan.clouds) break;
      const auto msg = m.instantiate<sensor_msgs::PointCloud2>();
      if (!msg) continue;
      msg->header.stamp = wall(msg->header.stamp - ros::Duration(plan.stamp_skew));
      waitUntil(wall(m.getTime()));
      points.publish(msg);
      ++clouds;
    } else if (m.getTopic() == kTfStatic) {
      if (const auto msg = m.instantiate<tf2_msgs::TFMessage>()) tf_static.publish(msg);
    } else if (const auto msg = m.instantiate<tf2_msgs::TFMessage>()) {
      for (geometry_msgs::TransformStamped& t : msg->transforms)
        if (!t.header.stamp.isZero()) t.header.stamp = wall(t.header.stamp - ros::Duration(plan.stamp_skew));
      waitUntil(wall(m.getTime()));
      tf.publish(msg);
    }
  }
  ros::WallDuration(0.5).sleep();  // the last messages leave the publisher's queue
  ros::shutdown();
  return clouds == plan.clouds ? 0 : 1;
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
    if (slot + 1 == slots_ && clouds_ > warmup_) end_ = Usage::now();
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
  std::string input, output;
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

}  // namespace

int runNodeletBench(const NodeletBenchOptions& o) {
  if (o.stages.empty() || o.stages.front() != "base")
    throw std::runtime_error("--stages must start with base: the nodelets are fed point clouds");
  if (o.rate <= 0) throw std::runtime_error("--rate must be > 0, not " + std::to_string(o.rate));
  auto has = [&](const char* s) { return std::find(o.stages.begin(), o.stages.end(), s) != o.stages.end(); };
  const bool intra = has("intra"), inter = has("inter"), tracker = has("track") || inter;
  std::vector<Stage> stages = {{"base", "ret3d_detector", "ret3d/DetectorNodelet", kPoints, "/detections"}};
  if (intra) stages.push_back({"intra", "ret3d_intra", "ret3d/IntraRMNodelet", "/detections", "/detections_intra"});
  if (tracker)
    stages.push_back({"track", "ret3d_tracker", "ret3d/TrackerNodelet", stages.back().output, "/tracked"});
  if (inter) stages.push_back({"inter", "ret3d_inter", "ret3d/InterRMNodelet", "/tracked", "/objects"});
  const std::string params = o.params.empty() ? packagePath() + "/config/ret3d.yaml" : o.params;
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

  // The player is forked before this process starts any ROS thread.
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
  ChildProcess player(player_pid);
  struct Fd {
    int fd;
    ~Fd() { close(fd); }
  } go_fd{go[1]};

  ros::M_string no_remappings;
  ros::init(no_remappings, "ret3d_bench");
  waitForMaster(&master);
  // The nodelets' INFO lines (listening on ..., warmed up) would bury the table; warnings and errors still show.
  if (ros::console::set_logger_level("ros", ros::console::levels::Warn)) ros::console::notifyLoggerLevelsChanged();

  Row input{"input", "  stamp to cloud in the manager (player, transport)"};
  std::vector<Row> rows;
  Row end_to_end{"end_to_end", "  stamp to " + stages.back().output};
  std::size_t frames = 0, frames_out = 0;
  Recorder::Cpu cpu;
  double player_cpu = 0;
  {
    ros::NodeHandle nh, private_nh("~");
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
    private_nh.setParam("num_worker_threads", o.manager_threads);

    std::cout << "bench: loading the nodelets into this process (the manager, " << o.manager_threads
              << " callback threads):";
    nodelet::Loader loader(private_nh);
    std::vector<std::pair<std::string, std::string>> load;
    for (const Stage& s : stages) load.emplace_back(s.nodelet, s.type);
    const bool markers = o.markers && inter;
    if (markers) load.emplace_back("ret3d_markers", "ret3d/MarkerNodelet");
    for (const auto& [name, type] : load) std::cout << " " << type;
    std::cout << std::endl;
    for (const auto& [name, type] : load) {
      ros::M_string remap;
      // Without IntraRM the tracker reads the detector's output, as launch/ret3d.launch remaps it with intra:=false.
      if (name == "ret3d_tracker" && !intra) remap["/detections_intra"] = "/detections";
      if (!loader.load("/" + name, type, remap, {}))
        throw std::runtime_error("nodelet " + name + " (" + type + ") did not start; see the message above");
    }

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

    std::cout << "bench: playing " << plan.clouds << " clouds of " << o.bag << " " << plan.topic << " at "
              << std::setprecision(1) << std::fixed << plan.cloud_rate_hz * o.rate << " Hz"
              << (o.rate != 1.0 ? " (--rate " + std::to_string(o.rate) + ")" : "") << " on " << kPoints
              << " from a player process, stamps moved to now" << (plan.tf ? ", with /tf" : ", no /tf in the bag")
              << (plan.tf_static ? " and /tf_static" : "") << "; " << o.warmup << " warm-up frames left out\n"
              << std::flush;
    if (write(go_fd.fd, "g", 1) != 1) throw std::runtime_error("the player process is gone");
    const ros::WallTime deadline = ros::WallTime::now() + ros::WallDuration(plan.duration / o.rate + 30.0 + o.tail);
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
      }
      if (player_done) {
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
    // The nodelets report once a second: one more report of each covers the last frames.
    std::vector<std::string> nodelets;
    for (const Stage& s : stages) nodelets.push_back(s.nodelet);
    const double ended = ros::WallTime::now().toSec();
    for (int i = 0; i < 150 && ros::ok() && !diagnostics.reportedSince(nodelets, ended); ++i)
      ros::WallDuration(0.01).sleep();
    spinner.stop();
    subscribers.clear();
    loader.clear();
    player_cpu = player.cpuSeconds();

    const auto measured = recorder.measured();
    frames = measured.size();
    for (std::size_t k = 0; k < stages.size(); ++k) {
      rows.emplace_back(stages[k].name, "  " + stages[k].input + " to " + stages[k].output + " (" + stages[k].type + ")");
      rows.back().processing_p50 = diagnostics.value(stages[k].nodelet, "processing p50 (ms)");
      rows.back().processing_p95 = diagnostics.value(stages[k].nodelet, "processing p95 (ms)");
    }
    for (const auto& [stamp, at] : measured) {
      input.ms.push_back(1e3 * (at[0] - stamp));
      for (std::size_t k = 0; k < stages.size(); ++k) {
        rows[k].in += std::isnan(at[k]) ? 0 : 1;
        if (!std::isnan(at[k]) && !std::isnan(at[k + 1])) rows[k].ms.push_back(1e3 * (at[k + 1] - at[k]));
        rows[k].out += std::isnan(at[k + 1]) ? 0 : 1;
      }
      if (!std::isnan(at.back())) {
        end_to_end.ms.push_back(1e3 * (at.back() - stamp));
        ++frames_out;
      }
    }
    input.in = input.out = frames;
    end_to_end.in = frames, end_to_end.out = frames_out;
    cpu = recorder.cpu();
  }
  ros::shutdown();
  master.stop(SIGINT);

  const unsigned cores = std::max(1u, std::thread::hardware_concurrency());
  const std::size_t dropped = frames - frames_out;
  std::cout << std::left << std::setw(12) << "stage" << std::right << std::setw(10) << "p50 ms" << std::setw(10)
            << "p95 ms" << std::setw(13) << "out/in" << std::setw(16) << "processing ms" << "\n";
  printRow(input, frames);
  for (const Row& r : rows) printRow(r, frames);
  printRow(end_to_end, frames);
  std::cout << "(p50 / p95 per cloud after the warm-up: from the arrival of a stage's input to that of its output, "
               "waiting included; processing p50 / p95: the stage's own /diagnostics over its last 200 frames)\n";
  std::cout << std::setprecision(1) << "frames: " << frames << " measured, " << frames_out << " with "
            << stages.back().output << ", " << dropped << " dropped (" << 100.0 * static_cast<double>(dropped) / std::max<std::size_t>(1, frames)
            << " %)\n"
            << std::setprecision(2) << "CPU: " << cpu.cores << " cores of " << cores << " (" << std::setprecision(0)
            << 100.0 * cpu.cores / cores << " %) used by the manager process over the " << std::setprecision(1)
            << cpu.seconds << " s measured; the player used " << player_cpu << " s of CPU in all\n"
            << "machine: " << cpu.steal_percent
            << " % of CPU time stolen by the hypervisor meanwhile (/proc/stat steal; above a few percent the timings "
               "say more about the host than about the pipeline)\n";

  if (!o.json.empty()) {
    std::ostringstream json;
    json << std::fixed << std::setprecision(3) << "{";
    auto add = [&](const Row& r) {
      json << "\"" << r.name << "\": {\"median_ms\": " << percentile(r.ms, 50) << ", \"p95_ms\": " << percentile(r.ms, 95)
           << ", \"frames_out\": " << r.out;
      if (r.processing_p50 >= 0)
        json << ", \"processing_median_ms\": " << r.processing_p50 << ", \"processing_p95_ms\": " << r.processing_p95;
      json << "}, ";
    };
    add(input);
    for (const Row& r : rows) add(r);
    add(end_to_end);
    json << "\"frames\": " << frames << ", \"frames_out\": " << frames_out << ", \"dropped\": " << dropped
         << ", \"warmup\": " << o.warmup << ", \"input_rate_hz\": " << plan.cloud_rate_hz * o.rate
         << ", \"cpu_cores\": " << cpu.cores << ", \"cpu_percent\": " << 100.0 * cpu.cores / cores
         << ", \"steal_percent\": " << cpu.steal_percent
         << ", \"cores\": " << cores << ", \"threads\": " << o.threads << "}\n";
    if (fs::path(o.json).has_parent_path()) fs::create_directories(fs::path(o.json).parent_path());
    std::ofstream(o.json) << json.str();
    std::cout << "bench: wrote " << o.json << "\n";
  }
  return 0;
}

}  // namespace tools
}  // namespace ret3d
