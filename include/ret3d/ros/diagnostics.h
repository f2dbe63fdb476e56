// What a stage nodelet reports on /diagnostics (diagnostic_updater): input rate, what became of every input frame,
// processing time of the stage and end-to-end latency (input cloud stamp to this stage's output), p50 / p95 over the
// last frames, and the last degradation (missing transform, bad cloud, stage error).
//
// Input accounting: every message the stage's subscriber hands over is either answered (an output published for it:
// "frames out") or dropped for one named reason ("dropped.<reason>"), so that at any quiet moment (nothing waiting,
// nothing in process) frames in == frames out + the sum of the dropped.* counters. An answered frame the stage had to
// work around (no intensity, malformed cloud answered with no detections, missing transform, ...) is also counted
// under "degraded.<kind>"; those counts are a breakdown of frames out, not extra frames.
#pragma once

#include <diagnostic_updater/DiagnosticStatusWrapper.h>
#include <ros/time.h>

#include <array>
#include <cstddef>
#include <deque>
#include <map>
#include <mutex>
#include <string>
#include <vector>

namespace ret3d {

// Why a frame got no output. Every reason is always reported (0 when it never happened).
enum class DropReason {
  Superseded,  // a newer message arrived while this one waited for the worker (latest-frame policy)
  TooOld,      // its stamp was older than the stage's ~max_input_age when the worker took it
  Error,       // the stage threw while processing it (logged)
};
constexpr std::size_t kNumDropReasons = 3;
// "superseded", "too_old", "error": the suffix of the dropped.* diagnostic keys.
const char* dropReasonName(DropReason reason);

class StageMonitor {
 public:
  explicit StageMonitor(std::size_t window = 200) : window_(window) {}

  void input();                     // a message arrived (wall time)
  void dropped(DropReason reason);  // a message that will get no output
  // A frame answered: processing time (wall, ms) and the input's header stamp (latency = ros::Time::now() - stamp).
  void processed(double processing_ms, const ros::Time& input_stamp);
  // Something the stage worked around on an answered frame; `kind` is a snake_case key (degraded.<kind>), `what`
  // the readable detail kept as the last degradation.
  void degraded(const std::string& kind, const std::string& what);

  struct Snapshot {
    std::size_t inputs = 0, processed = 0, degraded = 0;
    std::array<std::size_t, kNumDropReasons> dropped_by_reason{};
    std::map<std::string, std::size_t> degraded_by_kind;
    double input_rate_hz = 0;
    double processing_p50_ms = 0, processing_p95_ms = 0, processing_max_ms = 0;
    double latency_p50_ms = 0, latency_p95_ms = 0;
    std::string last_degradation;
    std::size_t dropped() const;  // sum over the reasons
  };
  Snapshot snapshot() const;
  // OK, or WARN when frames were dropped / the stage degraded in the last report period.
  void fill(diagnostic_updater::DiagnosticStatusWrapper& status);

 private:
  mutable std::mutex mutex_;
  std::size_t window_;
  std::deque<double> arrivals_;  // wall seconds, last 10 s
  std::deque<double> processing_ms_, latency_ms_;
  std::size_t inputs_ = 0, processed_ = 0, degraded_ = 0;
  std::array<std::size_t, kNumDropReasons> dropped_{};
  std::map<std::string, std::size_t> degraded_by_kind_;
  std::size_t reported_dropped_ = 0, reported_degraded_ = 0;
  std::string last_degradation_;
};

}  // namespace ret3d
