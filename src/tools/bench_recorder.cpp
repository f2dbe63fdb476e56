// The nodelet bench's CPU accounting and its table rows (tools/nodelet_bench_parts.h).
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

#include "ret3d/core/stats.h"
#include "tools/nodelet_bench_parts.h"

namespace ret3d {
namespace tools {
namespace bench {

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

void printRow(const Row& r, std::size_t frames) {
  std::ostringstream processing;
  processing << std::fixed << std::setprecision(1);
  if (r.processing_p50 >= 0) processing << r.processing_p50 << " / " << r.processing_p95;
  std::cout << std::left << std::setw(12) << r.name << std::right << std::fixed << std::setprecision(1)
            << std::setw(10) << percentile(r.ms, 50) << std::setw(10) << percentile(r.ms, 95) << std::setw(6)
            << r.out << "/" << std::left << std::setw(6) << (r.in ? r.in : frames) << std::right << std::setw(14)
            << processing.str() << "  " << r.what << "\n";
}

}  // namespace bench
}  // namespace tools
}  // namespace ret3d
