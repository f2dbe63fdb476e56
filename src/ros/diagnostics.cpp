// Stage statistics for /diagnostics (include/ret3d/ros/diagnostics.h).
#include "ret3d/ros/diagnostics.h"

#include <algorithm>
#include <cmath>
#include <diagnostic_msgs/DiagnosticStatus.h>
#include <ros/ros.h>

#include "ret3d/core/enum_names.h"
#include "ret3d/core/stats.h"

namespace ret3d {

const char* dropReasonName(DropReason reason) {
  static constexpr std::array<const char*, kNumDropReasons> kNames = {"superseded", "too_old", "error"};
  static_assert(static_cast<std::size_t>(DropReason::Error) + 1 == kNumDropReasons);
  return enumName(reason, kNames, "unknown");
}

std::size_t StageMonitor::Snapshot::dropped() const {
  std::size_t sum = 0;
  for (const std::size_t n : dropped_by_reason) sum += n;
  return sum;
}

void StageMonitor::input() {
  const double now = ros::WallTime::now().toSec();
  std::lock_guard<std::mutex> lock(mutex_);
  ++inputs_;
  arrivals_.push_back(now);
  while (!arrivals_.empty() && arrivals_.front() < now - 10.0) arrivals_.pop_front();
}

void StageMonitor::dropped(DropReason reason) {
  std::lock_guard<std::mutex> lock(mutex_);
  ++dropped_[static_cast<std::size_t>(reason)];
}

void StageMonitor::processed(double processing_ms, const ros::Time& input_stamp) {
  const double latency_ms = (ros::Time::now() - input_stamp).toSec() * 1e3;
  std::lock_guard<std::mutex> lock(mutex_);
  ++processed_;
  processing_ms_.push_back(processing_ms);
  latency_ms_.push_back(latency_ms);
  while (processing_ms_.size() > window_) processing_ms_.pop_front();
  while (latency_ms_.size() > window_) latency_ms_.pop_front();
}

void StageMonitor::degraded(const std::string& kind, const std::string& what) {
  std::lock_guard<std::mutex> lock(mutex_);
  ++degraded_;
  ++degraded_by_kind_[kind];
  last_degradation_ = what;
}

StageMonitor::Snapshot StageMonitor::snapshot() const {
  std::lock_guard<std::mutex> lock(mutex_);
  Snapshot s;
  s.inputs = inputs_;
  s.processed = processed_;
  s.dropped_by_reason = dropped_;
  s.degraded = degraded_;
  s.degraded_by_kind = degraded_by_kind_;
  if (arrivals_.size() >= 2) {
    const double span = arrivals_.back() - arrivals_.front();
    if (span > 0) s.input_rate_hz = static_cast<double>(arrivals_.size() - 1) / span;
  }
  const std::vector<double> proc(processing_ms_.begin(), processing_ms_.end());
  const std::vector<double> lat(latency_ms_.begin(), latency_ms_.end());
  s.processing_p50_ms = percentile(proc, 50);
  s.processing_p95_ms = percentile(proc, 95);
  s.processing_max_ms = proc.empty() ? 0.0 : *std::max_element(proc.begin(), proc.end());
  s.latency_p50_ms = percentile(lat, 50);
  s.latency_p95_ms = percentile(lat, 95);
  s.last_degradation = last_degradation_;
  return s;
}

void StageMonitor::fill(diagnostic_updater::DiagnosticStatusWrapper& status) {
  const Snapshot s = snapshot();
  std::size_t new_drops = 0, new_degraded = 0;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    new_drops = s.dropped() - reported_dropped_;
    new_degraded = s.degraded - reported_degraded_;
    reported_dropped_ = s.dropped();
    reported_degraded_ = s.degraded;
  }
  if (new_drops > 0 || new_degraded > 0) {
    status.summaryf(diagnostic_msgs::DiagnosticStatus::WARN, "%zu frames dropped, %zu degraded since last report%s%s",
                    new_drops, new_degraded, s.last_degradation.empty() ? "" : ": ", s.last_degradation.c_str());
  } else {
    status.summary(diagnostic_msgs::DiagnosticStatus::OK, "OK");
  }
  status.add("input rate (Hz)", s.input_rate_hz);
  status.add("frames in", s.inputs);
  status.add("frames out", s.processed);
  status.add("frames dropped", s.dropped());
  for (std::size_t r = 0; r < kNumDropReasons; ++r) {
    status.add(std::string("dropped.") + dropReasonName(static_cast<DropReason>(r)), s.dropped_by_reason[r]);
  }
  status.add("frames degraded", s.degraded);
  for (const auto& [kind, n] : s.degraded_by_kind) status.add("degraded." + kind, n);
  status.add("processing p50 (ms)", s.processing_p50_ms);
  status.add("processing p95 (ms)", s.processing_p95_ms);
  status.add("processing max (ms)", s.processing_max_ms);
  status.add("latency since cloud stamp p50 (ms)", s.latency_p50_ms);
  status.add("latency since cloud stamp p95 (ms)", s.latency_p95_ms);
  if (!s.last_degradation.empty()) status.add("last degradation", s.last_degradation);
}

}  // namespace ret3d
