// The nodelet bench's soak (--loop-frames): this process sampled per window, and the acceptance checks
// (tools/nodelet_bench_parts.h).
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

#include "ret3d/core/json_writer.h"
#include "ret3d/core/stats.h"
#include "tools/nodelet_bench_parts.h"

namespace ret3d {
namespace tools {
namespace bench {

namespace fs = std::filesystem;

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

void Soak::print(const SoakWindow& w) {
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

namespace {

// The acceptance checks over the windows. The reference is frame K = 1000 (less on a run shorter than 2000 frames:
// half the run, in whole windows): resident memory from frame K to the end grows by less than 5 %; the descriptor
// count at the end equals frame K's; the end-to-end p95 of the last K frames is at most 10 % above that of the first K.
struct SoakChecks {
  std::size_t frames = 0, every = 0, k = 0, measured = 0, answered = 0;
  const SoakWindow* ref = nullptr;
  const SoakWindow* end = nullptr;
  bool checks = false, rss_ok = false, fds_ok = false, p95_ok = false;
  double rss_growth = 0, p95_first = 0, p95_last = 0, p95_change = 0, max_rss = 0;
  int min_fds = 0, max_fds = 0;
};

SoakChecks checkSoak(const std::vector<SoakWindow>& windows, std::size_t every) {
  SoakChecks c;
  c.frames = windows.back().frame, c.every = every;
  c.k = std::min<std::size_t>(1000, c.frames / 2 / every * every);
  // End-to-end latencies of the windows within the first and the last K frames (with a partial last window, the
  // windows starting at or after frame `frames - K`).
  std::vector<double> first, last;
  for (const SoakWindow& w : windows) {
    if (w.frame == c.k) c.ref = &w;
    if (w.frame > 0 && w.frame <= c.k) first.insert(first.end(), w.end_to_end_ms.begin(), w.end_to_end_ms.end());
    if (w.frame > c.k && w.frame >= c.frames - c.k + every)
      last.insert(last.end(), w.end_to_end_ms.begin(), w.end_to_end_ms.end());
    c.measured += w.measured, c.answered += w.answered;
  }
  c.end = &windows.back();
  c.checks = c.ref != nullptr && c.k > 0;
  c.rss_growth = c.checks ? 100.0 * (c.end->process.rss_mb - c.ref->process.rss_mb) / c.ref->process.rss_mb : 0;
  c.p95_first = percentile(first, 95), c.p95_last = percentile(last, 95);
  c.p95_change = c.p95_first > 0 ? 100.0 * (c.p95_last - c.p95_first) / c.p95_first : 0;
  c.rss_ok = c.checks && c.rss_growth < 5.0, c.fds_ok = c.checks && c.end->process.fds == c.ref->process.fds;
  c.p95_ok = c.checks && !first.empty() && !last.empty() && c.p95_change <= 10.0;
  c.min_fds = c.max_fds = c.end->process.fds;
  for (const SoakWindow& w : windows)
    if (w.frame > 0) {
      c.min_fds = std::min(c.min_fds, w.process.fds), c.max_fds = std::max(c.max_fds, w.process.fds);
      c.max_rss = std::max(c.max_rss, w.process.rss_mb);
    }
  return c;
}

void printSoak(const SoakChecks& c, const NodeletBenchOptions& o, double rate_hz, const std::string& last_output) {
  std::cout << std::fixed << std::setprecision(1) << "soak: " << c.frames << " frames at " << rate_hz << " Hz, "
            << c.answered << " of " << c.measured << " measured clouds answered on " << last_output << " ("
            << c.measured - c.answered << " skipped by the latest-frame policy or late)";
  if (o.load > 0) std::cout << ", " << o.load << " cores kept busy (--load)";
  std::cout << "\n";
  if (!c.checks) {
    std::cout << "soak: too short for the checks (they need two windows of --soak-every " << c.every
              << " frames before and after a reference frame)\n";
    return;
  }
  auto verdict = [](bool ok) { return ok ? "PASS" : "FAIL"; };
  std::cout << std::setprecision(1) << "soak check: resident memory frame " << c.k << " -> " << c.frames << ": "
            << c.ref->process.rss_mb << " -> " << c.end->process.rss_mb << " MB (" << std::showpos << c.rss_growth
            << std::noshowpos << " %, limit < +5 %; peak " << c.max_rss << " MB)  " << verdict(c.rss_ok) << "\n"
            << "soak check: open file descriptors frame " << c.k << " -> " << c.frames << ": " << c.ref->process.fds
            << " -> " << c.end->process.fds << " (range " << c.min_fds << "-" << c.max_fds << " over the run)  "
            << verdict(c.fds_ok) << "\n"
            << "soak check: end-to-end p95 first " << c.k << " frames " << c.p95_first << " ms, last " << c.k
            << " frames " << c.p95_last << " ms (" << std::showpos << c.p95_change << std::noshowpos
            << " %, limit +10 %)  " << verdict(c.p95_ok) << "\n"
            << "soak: " << (c.rss_ok && c.fds_ok && c.p95_ok ? "all checks pass" : "CHECKS FAILED") << "\n";
}

// One window's samples as a JSON object and a row of the table for the plot.
void addWindow(const SoakWindow& w, double t, JsonWriter* json, std::ostringstream* table) {
  const double max = w.end_to_end_ms.empty() ? 0.0 : *std::max_element(w.end_to_end_ms.begin(), w.end_to_end_ms.end());
  json->beginObject()
      .field("frame", w.frame)
      .field("wall_s", t)
      .field("rss_mb", w.process.rss_mb)
      .field("fds", w.process.fds)
      .field("threads", w.process.threads)
      .field("machine_load", w.process.machine_load);
  if (w.frame > 0)
    json->field("cpu_cores", w.cpu_cores)
        .field("end_to_end_p50_ms", percentile(w.end_to_end_ms, 50))
        .field("end_to_end_p95_ms", percentile(w.end_to_end_ms, 95))
        .field("end_to_end_max_ms", max)
        .field("detector_p50_ms", percentile(w.base_ms, 50))
        .field("detector_p95_ms", percentile(w.base_ms, 95))
        .field("answered", w.answered)
        .field("measured", w.measured);
  json->endObject();
  if (w.frame > 0)
    *table << w.frame << "\t" << t << "\t" << w.process.rss_mb << "\t" << w.process.fds << "\t" << w.process.threads
           << "\t" << w.cpu_cores << "\t" << percentile(w.end_to_end_ms, 50) << "\t"
           << percentile(w.end_to_end_ms, 95) << "\t" << max << "\t" << percentile(w.base_ms, 50) << "\t"
           << percentile(w.base_ms, 95) << "\t" << w.answered << "\t" << w.measured << "\t"
           << w.process.machine_load << "\n";
}

void writeSoakJson(const std::vector<SoakWindow>& windows, const SoakChecks& c, const NodeletBenchOptions& o,
                   double rate_hz) {
  JsonWriter json({/*decimals=*/3});
  json.field("frames", c.frames)
      .field("every", c.every)
      .field("rate_hz", rate_hz)
      .field("load", o.load)
      .field("warmup", o.warmup)
      .field("measured", c.measured)
      .field("answered", c.answered)
      .beginArray("samples");
  std::ostringstream table;
  table << "# frame\twall_s\trss_mb\tfds\tthreads\tcpu_cores\te2e_p50_ms\te2e_p95_ms\te2e_max_ms\tdetector_p50_ms\t"
           "detector_p95_ms\tanswered\tmeasured\tmachine_load\n"
        << std::fixed << std::setprecision(3);
  for (const SoakWindow& w : windows) addWindow(w, w.process.wall_s - windows.front().process.wall_s, &json, &table);
  json.endArray();
  if (c.checks)
    json.beginObject("checks")
        .field("reference_frame", c.k)
        .field("rss_reference_mb", c.ref->process.rss_mb)
        .field("rss_end_mb", c.end->process.rss_mb)
        .field("rss_growth_percent", c.rss_growth)
        .field("fds_reference", c.ref->process.fds)
        .field("fds_end", c.end->process.fds)
        .field("p95_first_ms", c.p95_first)
        .field("p95_last_ms", c.p95_last)
        .field("p95_change_percent", c.p95_change)
        .field("rss_ok", c.rss_ok)
        .field("fds_ok", c.fds_ok)
        .field("p95_ok", c.p95_ok)
        .field("passed", c.rss_ok && c.fds_ok && c.p95_ok)
        .endObject();
  json.save(o.json);
  const std::string tsv = fs::path(o.json).replace_extension(".tsv").string();
  std::ofstream(tsv) << table.str();
  std::cout << "bench: wrote " << o.json << " and " << tsv << "\n";
}

}  // namespace

void reportSoak(const std::vector<SoakWindow>& windows, const NodeletBenchOptions& o, double rate_hz,
                const std::string& last_output) {
  const SoakChecks c = checkSoak(windows, static_cast<std::size_t>(o.soak_every));
  printSoak(c, o, rate_hz, last_output);
  if (!o.json.empty()) writeSoakJson(windows, c, o, rate_hz);
}

}  // namespace bench
}  // namespace tools
}  // namespace ret3d
