// The pipeline timed through the real nodelets in one manager (src/tools/nodelet_bench.h): the run and its report.
// Its parts: tools/nodelet_bench_parts.h.
#include "tools/nodelet_bench.h"

#include <nodelet/loader.h>
#include <ros/ros.h>
#include <sensor_msgs/PointCloud2.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <iomanip>
#include <iostream>
#include <optional>
#include <stdexcept>
#include <thread>

#include "ret3d/DetectionArray.h"
#include "ret3d/Object3DArray.h"
#include "ret3d/core/json_writer.h"
#include "ret3d/core/stats.h"
#include "ret3d/ros/params.h"
#include "tools/nodelet_bench_parts.h"

namespace ret3d {
namespace tools {
namespace bench {
namespace {

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
}  // namespace bench

using namespace bench;

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
