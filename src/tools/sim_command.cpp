// `ret3d sim --config config/sim/<preset>.yaml --out DIR --sequences N --frames F --seed S [--sensor NAME] [--bag]
//  [--replay KITTI_TRACKING_DIR --replay-sequence SSSS]`: simulated LiDAR sequences in the KITTI tracking layout
// (src/sim, docs/SIMULATOR.md), optionally converted to bags, with a closing summary.
#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "ret3d/core/progress.h"
#include "ret3d/core/stats.h"
#include "ret3d/ros/kitti_bag.h"
#include "ret3d/sim/realism.h"
#include "ret3d/sim/simulator.h"
#include "tools/command.h"

namespace ret3d {
namespace tools {
namespace {

struct SimArgs {
  std::string config, out, sensor, replay, replay_sequence = "0000", stats_out;
  std::vector<std::string> stats, compare;
  int sequences = 1, frames = 100, threads = 2;
  std::uint64_t seed = 0;
  bool bag = false;
};

std::string fmt(double v, int digits = 1) {
  char b[64];
  std::snprintf(b, sizeof(b), "%.*f", digits, v);
  return b;
}

// `--stats DATASET --stats-out PREFIX`: realism statistics of any KITTI-layout data (scripts/experiments/sim_realism.sh).
int runStats(const SimArgs& args) {
  // Sensor models live in config/sensors of the package: next to --config's config/sim when given, else under the
  // working directory (the package root).
  const std::string root = args.config.empty()
                               ? std::string(".")
                               : std::filesystem::absolute(args.config).parent_path().parent_path().parent_path().string();
  const sim::SensorModel sensor = args.sensor.empty() ? sim::sensorByName("hdl64e", root)
                                  : std::filesystem::path(args.sensor).extension() == ".yaml"
                                      ? sim::loadSensorModel(args.sensor)
                                      : sim::sensorByName(args.sensor, root);
  sim::ScanStats s;
  std::string names;
  for (const auto& dir : args.stats) {
    sim::addDataset(s, dir, sensor, args.frames);
    names += (names.empty() ? "" : " + ") + dir;
  }
  s.finish();
  s.write(args.stats_out);
  const double zero = s.zero_hist.empty() ? 0.0 : s.zero_hist[0] / std::max(1e-9, s.zero_hist[0] + s.zero_hist[1]);
  std::cout << names << ": " << s.frames << " frames, " << fmt(static_cast<double>(s.points) / s.frames, 0)
            << " points per frame, mean intensity " << fmt(s.mean_intensity, 3) << ", cars " << s.cars.size()
            << "; median points on a car at 10 m " << fmt(s.medianCarPoints(7, 13), 0) << ", 20 m "
            << fmt(s.medianCarPoints(16, 24), 0) << ", 40 m " << fmt(s.medianCarPoints(33, 47), 0)
            << "; zero-intensity returns " << fmt(100 * zero, 1) << " %" << std::endl;
  return 0;
}

// `--compare A B`: Wasserstein-1 distance per statistic between the --stats .dat files under prefixes A and B.
int runCompare(const SimArgs& args) {
  std::cout << "statistic   W1 (" << args.compare[0] << " vs " << args.compare[1] << ")\n";
  for (const auto& d : sim::compareStats(args.compare[0], args.compare[1])) {
    std::cout << d.name << std::string(d.name.size() < 12 ? 12 - d.name.size() : 1, ' ') << fmt(d.w1, 4)
              << (d.unit.empty() ? "" : " " + d.unit) << "\n";
  }
  std::cout << std::flush;
  return 0;
}

// The simulator's options from the arguments: the scenario, the sensor (a YAML path, or a name under config/sensors
// next to the scenario's config/sim), the output, frames, seed and replay.
sim::SimOptions simOptions(const SimArgs& args) {
  namespace fs = std::filesystem;
  sim::SimOptions opt;
  opt.config = sim::loadSimConfig(args.config);
  const std::string sensor = args.sensor.empty() ? opt.config.sensor : args.sensor;
  if (fs::path(sensor).extension() == ".yaml") {
    opt.sensor = sim::loadSensorModel(sensor);
  } else {
    const fs::path root = fs::absolute(args.config).parent_path().parent_path().parent_path();
    opt.sensor = sim::sensorByName(sensor, root.string());
  }
  opt.out_dir = args.out;
  opt.frames = args.frames;
  opt.seed = args.seed;
  opt.threads = args.threads;
  opt.replay_dir = args.replay;
  opt.replay_sequence = args.replay_sequence;
  return opt;
}

// The summary on stdout: frames, points per frame, objects and tracks per class, points per object, time per frame.
void printSimSummary(const std::vector<sim::SequenceReport>& reports) {
  std::vector<double> times, points, near;
  std::map<std::string, std::size_t> objects, tracks;
  std::size_t object_points = 0, total_objects = 0;
  double setup = 0;
  std::map<std::string, int> sequences_with;
  for (const auto& r : reports) {
    for (const auto& f : r.frames) {
      times.push_back(f.seconds);
      points.push_back(static_cast<double>(f.points));
      near.push_back(static_cast<double>(f.objects_within_50m));
    }
    for (const auto& [k, v] : r.objects) {
      objects[k] += v;
      total_objects += v;
    }
    for (const auto& [k, v] : r.tracks) {
      tracks[k] += v;
      if (v > 0) ++sequences_with[k];
    }
    object_points += r.object_points;
    setup += r.setup_seconds;
  }
  const std::size_t n = times.size();
  auto mean = [](const std::vector<double>& v) {
    double s = 0;
    for (double x : v) s += x;
    return v.empty() ? 0.0 : s / v.size();
  };
  double total_time = 0;
  for (double t : times) total_time += t;
  const double med = median(times);
  std::cout << "\nsummary\n";
  std::cout << "  frames               " << n << " in " << reports.size() << " sequence(s)\n";
  if (n > 0) {
    std::cout << "  points per frame     mean " << fmt(mean(points), 0) << ", median " << fmt(median(points), 0)
              << ", min " << fmt(*std::min_element(points.begin(), points.end()), 0) << ", max "
              << fmt(*std::max_element(points.begin(), points.end()), 0) << "\n";
  }
  std::cout << "  objects per class    ";
  for (const char* c : {"Car", "Pedestrian", "Cyclist", "Van", "Truck"}) {
    if (objects[c] == 0 && (std::string(c) == "Van" || std::string(c) == "Truck")) continue;  // only when drawn
    std::cout << c << " " << objects[c] << " (" << tracks[c] << " tracks, in " << sequences_with[c] << "/"
              << reports.size() << " sequences)  ";
  }
  std::cout << "\n";
  std::cout << "  objects per frame    " << fmt(n ? static_cast<double>(total_objects) / n : 0.0, 1)
            << " labelled, " << fmt(mean(near), 1) << " within 50 m\n";
  std::cout << "  points per object    " << fmt(total_objects ? static_cast<double>(object_points) / total_objects : 0.0, 1)
            << " (mean num_points)\n";
  std::cout << "  time per frame       median " << fmt(1000 * med, 1) << " ms, mean " << fmt(1000 * mean(times), 1)
            << " ms (motion, ray casting, labels, writing); setup " << fmt(setup, 2) << " s\n";
  std::cout << "  frames/s             " << fmt(med > 0 ? 1.0 / med : 0.0, 1) << " (median), "
            << fmt(total_time > 0 ? n / total_time : 0.0, 1) << " (overall, without setup)\n";
}

int runSim(const SimArgs& args) {
  namespace fs = std::filesystem;
  if (!args.compare.empty()) return runCompare(args);
  if (!args.stats.empty()) return runStats(args);
  if (args.config.empty() || args.out.empty()) throw std::runtime_error("--config and --out are required");
  const sim::SimOptions opt = simOptions(args);
  if (args.sequences < 1) throw std::runtime_error("--sequences must be at least 1");
  if (args.frames < 1 && args.replay.empty()) throw std::runtime_error("--frames must be at least 1");
  const int sequences = args.replay.empty() ? args.sequences : 1;
  fs::create_directories(args.out);

  std::cout << "ret3d sim: " << opt.config.name << " (" << args.config << "), sensor " << opt.sensor.name << " ("
            << opt.sensor.beams() << " beams x " << opt.sensor.columns() << " columns), " << sequences
            << " sequence(s)" << (args.replay.empty() ? " x " + std::to_string(args.frames) + " frames" : ", replay of " + args.replay + " " + args.replay_sequence)
            << ", seed " << args.seed << " -> " << args.out << std::endl;
  ProgressBar bar("sim", static_cast<std::size_t>(sequences) * static_cast<std::size_t>(std::max(args.frames, 1)));
  std::vector<sim::SequenceReport> reports;
  for (int s = 0; s < sequences; ++s) {
    reports.push_back(sim::simulateSequence(opt, s, [&](const sim::FrameReport& f) {
      bar.tick(1, "seq " + std::to_string(f.sequence) + "  " + std::to_string(f.points) + " pts  " +
                      std::to_string(f.objects) + " objects");
    }));
  }
  bar.finish();
  printSimSummary(reports);

  if (args.bag) {
    for (const auto& r : reports) {
      ConvertOptions co;
      co.sequence = r.name;
      co.rate = opt.config.frame_rate;
      co.sensor_height = opt.sensor.mount_height;
      const std::string bag = args.out + "/" + r.name + ".bag";
      const std::size_t frames = convertKittiToBag(args.out, bag, co);
      std::cout << "  bag                  " << bag << " (" << frames << " frames)\n";
    }
  }
  std::cout << std::flush;
  return 0;
}

CommandRegistrar registrar(
    "sim", "simulated LiDAR driving sequences (KITTI tracking layout, optionally bags)", [](CLI::App& app) -> CommandRun {
      auto args = std::make_shared<SimArgs>();
      app.footer(
          "Writes DIR/training/{velodyne/SSSS/FFFFFF.bin, label_02, calib, pose, sim_info}/SSSS.txt (docs/SIMULATOR.md). "
          "The same config, seed and options give byte-identical files.");
      app.add_option("--config", args->config, "scenario YAML, e.g. config/sim/urban_street.yaml (required)")
          ->check(CLI::ExistingFile);
      app.add_option("--out", args->out, "output dataset folder (required)");
      app.add_option("--stats", args->stats,
                     "instead of simulating: realism statistics (range, intensity, ring, height, zero-intensity, BEV "
                     "scatter and points-per-cell histograms; points on cars) of these KITTI-layout datasets or "
                     "folders of .bin scans pooled, at most --frames frames from each")
          ->check(CLI::ExistingDirectory);
      app.add_option("--compare", args->compare,
                     "instead of simulating: Wasserstein-1 distance per statistic between the --stats files of two "
                     "--stats-out prefixes, e.g. --compare out/sim out/real")
          ->expected(2);
      app.add_option("--stats-out", args->stats_out, "prefix of the --stats .dat files")->default_val("realism");
      app.add_option("--sequences", args->sequences, "number of sequences (seed + index each)")->capture_default_str();
      app.add_option("--frames", args->frames, "frames per sequence (replay: at most)")->capture_default_str();
      app.add_option("--seed", args->seed, "random seed")->capture_default_str();
      app.add_option("--sensor", args->sensor, "sensor model: hdl64e, vlp32c, os1_64 or a YAML path (default: the config's)");
      app.add_option("--threads", args->threads, "ray casting threads")->capture_default_str();
      app.add_flag("--bag", args->bag, "also convert each sequence to DIR/SSSS.bag (as `ret3d convert`)");
      app.add_option("--replay", args->replay, "KITTI tracking dataset whose label_02 + pose (+ calib) to replay")
          ->check(CLI::ExistingDirectory);
      app.add_option("--replay-sequence", args->replay_sequence, "sequence to replay")->capture_default_str();
      return [args]() { return runSim(*args); };
    });

}  // namespace
}  // namespace tools
}  // namespace ret3d
