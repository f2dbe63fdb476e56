// Shared by the pipeline rostests (test/nodes/pipeline_*_test.cpp): a rosconsole appender that keeps every log line
// (to check what a nodelet said), a wait helper, and the in-process loading of the real nodelets.
#pragma once

#include <fcntl.h>
#include <nodelet/loader.h>
#include <ros/console.h>
#include <ros/ros.h>
#include <signal.h>
#include <spawn.h>
#include <sys/wait.h>

#include <chrono>
#include <functional>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

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
