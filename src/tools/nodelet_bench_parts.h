// The parts of the nodelet bench (`ret3d bench --bag`, tools/nodelet_bench.h), shared by its files: the bag and its
// player (bench_player.cpp), child processes and the private master (bench_process.cpp), the nodelets' parameters
// and loading (bench_params.cpp), the recorders and CPU accounting (here and bench_recorder.cpp), the soak
// (bench_soak.cpp); nodelet_bench.cpp runs them and reports. Private to src/tools.
#pragma once

#include <signal.h>
#include <sys/resource.h>
#include <sys/types.h>
#include <sys/wait.h>
#include <unistd.h>

#include <diagnostic_msgs/DiagnosticArray.h>
#include <nodelet/loader.h>
#include <ros/ros.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <deque>
#include <map>
#include <mutex>
#include <string>
#include <thread>
#include <utility>
#include <vector>

#include "tools/nodelet_bench.h"

namespace ret3d {
namespace tools {
namespace bench {

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

// Reads the bag's index: its cloud topic, how many clouds are played, their rate and times; throws naming the bag.
BagPlan scanBag(const NodeletBenchOptions& o);
// The player process's body (bench_player.cpp): plays the bag once a byte arrives on go_fd; returns the exit code.
int playBag(const NodeletBenchOptions& o, const BagPlan& plan, int go_fd);

// ---- child processes (bench_process.cpp) --------------------------------------------------------------------------

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
int freePort();
// `rosmaster --core -p PORT`, ending with this process (PR_SET_PDEATHSIG).
pid_t spawnMaster(int port);
// After ros::init: the master answers, or a runtime_error after 15 s (at once when `master` has ended).
void waitForMaster(ChildProcess* master = nullptr);
// The write end of the pipe that starts the player.
struct PipeEnd {
  int fd;
  ~PipeEnd() { close(fd); }
};

// Forks the bag player; it starts playing when a byte arrives on *go_fd. Call before this process starts any ROS
// thread.
pid_t forkPlayer(const NodeletBenchOptions& o, const BagPlan& plan, int* go_fd);

// ---- the nodelets: parameters and loading (bench_params.cpp) --------------------------------------------------

struct Stage {
  std::string name;      // key in the table and the JSON (as `ret3d bench --data`)
  std::string nodelet;   // node name, as launch/ret3d.launch
  std::string type;      // plugin
  std::string input, output;                  // absolute topics, after the remaps
  std::map<std::string, std::string> remaps;  // relative topic names, from -> to
};

// Refuses options out of range, naming them.
void checkOptions(const NodeletBenchOptions& o);
bool hasStage(const std::vector<Stage>& stages, const std::string& name);
// The nodelets of --stages in pipeline order, as launch/ret3d.launch loads them (pipeline/stage_layout.h).
std::vector<Stage> pipelineStages(const NodeletBenchOptions& o);
// The nodelets' parameters: the package's YAML (as `rosparam load` with subst_value), then what the options override.
void setNodeletParams(const NodeletBenchOptions& o, const std::string& params);
// Loads the stages' nodelets (and the markers with InterRM) into `loader`; throws naming one that did not start.
void loadNodelets(nodelet::Loader& loader, const std::vector<Stage>& stages, const NodeletBenchOptions& o);

// ---- recorders and CPU accounting (bench_recorder.cpp) ----------------------------------------------------------

// CPU seconds (user + system) this process has used.
double cpuSecondsOfThisProcess();
// Ticks of the whole machine from /proc/stat: {steal, all}; {0, 0} when unreadable.
std::pair<double, double> machineTicks();

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

struct Row {
  Row(std::string n, std::string w) : name(std::move(n)), what(std::move(w)) {}
  std::string name, what;
  std::vector<double> ms;
  std::size_t in = 0, out = 0;
  double processing_p50 = -1, processing_p95 = -1;  // the stage's own /diagnostics (< 0: none)
};

// One line of the table.
void printRow(const Row& r, std::size_t frames);

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

// ---- the soak, --loop-frames (bench_soak.cpp) ----------------------------------------------------------------

// What /proc says about this process, the one hosting the nodelets.
struct ProcessSample {
  double wall_s = 0, cpu_s = 0;  // wall clock and CPU seconds used so far
  double rss_mb = 0;             // VmRSS
  int fds = 0, threads = 0;      // entries of /proc/self/fd, Threads
  double machine_load = 0;       // the machine's 1-minute load average: what the latencies of a shared host follow
};

ProcessSample sampleThisProcess();

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
  static void print(const SoakWindow& w);  // one line per window

  Recorder* recorder_;
  double settle_s_;
  std::deque<Pending> pending_;
  std::vector<SoakWindow> windows_;  // windows_[0]: the sample before the first cloud
};

// The acceptance checks over the windows printed, and the JSON and the table for the plot (scripts/soak.sh) written:
// bench_soak.cpp says which.
void reportSoak(const std::vector<SoakWindow>& windows, const NodeletBenchOptions& o, double rate_hz,
                const std::string& last_output);

}  // namespace bench
}  // namespace tools
}  // namespace ret3d
