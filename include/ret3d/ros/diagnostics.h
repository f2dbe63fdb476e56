// What a stage nodelet reports on /diagnostics (diagnostic_updater): input rate, frames dropped by the latest-frame
// policy, processing time of the stage and end-to-end latency (input cloud stamp to this stage's output), p50 / p95
// over the last frames, and the last degradation (missing transform, bad cloud, stage error).
#pragma once

#include <diagnostic_updater/DiagnosticStatusWrapper.h>
#include <ros/time.h>

#include <cstddef>
#include <deque>
#include <mutex>
#include <string>
#include <vector>

namespace ret3d {

// Linear-interpolated percentile (p in [0, 100]) of the values; 0 for none.
double percentile(std::vector<double> values, double p);

class StageMonitor {
 public:
  explicit StageMonitor(std::size_t window = 200) : window_(window) {}

  void input();                 // a message arrived (wall time)
  void dropped();               // a waiting message was replaced by a newer one
  // A frame done: processing time (wall, ms) and the input's header stamp (latency = ros::Time::now() - stamp).
  void processed(double processing_ms, const ros::Time& input_stamp);
  void degraded(const std::string& what);  // the last thing the stage worked around

  struct Snapshot {
    std::size_t inputs = 0, processed = 0, dropped = 0, degraded = 0;
    double input_rate_hz = 0;
    double processing_p50_ms = 0, processing_p95_ms = 0, processing_max_ms = 0;
    double latency_p50_ms = 0, latency_p95_ms = 0;
    std::string last_degradation;
  };
  Snapshot snapshot() const;
  // OK, or WARN when frames were dropped / the stage degraded in the last report period.
  void fill(diagnostic_updater::DiagnosticStatusWrapper& status);

 private:
  mutable std::mutex mutex_;
  std::size_t window_;
  std::deque<double> arrivals_;  // wall seconds, last 10 s
  std::deque<double> processing_ms_, latency_ms_;
  std::size_t inputs_ = 0, processed_ = 0, dropped_ = 0, degraded_ = 0;
  std::size_t reported_dropped_ = 0, reported_degraded_ = 0;
  std::string last_degradation_;
};

}  // namespace ret3d
