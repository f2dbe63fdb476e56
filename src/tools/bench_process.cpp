// The nodelet bench's child processes: the private ROS master, the player's fork, the busy load
// (tools/nodelet_bench_parts.h).
#include <fcntl.h>
#include <netinet/in.h>
#include <sys/prctl.h>
#include <sys/socket.h>

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

#include "tools/nodelet_bench_parts.h"

namespace ret3d {
namespace tools {
namespace bench {

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
void waitForMaster(ChildProcess* master) {
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

}  // namespace bench

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

}  // namespace tools
}  // namespace ret3d
