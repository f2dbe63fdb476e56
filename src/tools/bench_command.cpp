// `ret3d bench --data DIR|--bag FILE --models DIR [--stages LIST] [--json FILE]`: times the pipeline.
// --bag FILE: through the real nodelets in one manager (tools/nodelet_bench.h): the bag played at its rate from a
// player process, per-stage times and end-to-end latency (cloud stamp to /objects) p50 / p95, drops, CPU use.
// --data DIR (or --bag FILE --in-process): each stage called in this process over real frames, after a warm-up; the
// median and p95 per stage (the base detector split into BEV, network, decoding and NMS). Scans come from a KITTI
// tracking or object folder, a folder of .bin scans, or the PointCloud2 messages of a bag. Frames are cycled until
// --min-runs timed runs, so a short drive still gives a p95.
// Neither: the stages after the detector timed on synthetic frames of --objects objects.
#include <algorithm>
#include <cmath>
#include <sstream>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <iostream>
#include <random>
#include <thread>

#include <rosbag/bag.h>
#include <rosbag/view.h>
#include <sensor_msgs/PointCloud2.h>

#include "ret3d/core/log.h"
#include "ret3d/io/kitti.h"
#include "ret3d/io/sweeps.h"
#include "ret3d/ros/conversions.h"
#include "ret3d/ros/params.h"
#include "tools/command.h"
#include "tools/nodelet_bench.h"
#include "tools/offline_pipeline.h"

namespace ret3d {
namespace tools {
namespace {

namespace fs = std::filesystem;

struct BenchArgs {
  PipelineConfig pipeline;
  std::string data, bag, topic, stages = "base,intra,track,inter", json, sequence, objects = "50,300";
  int warmup = 5, min_runs = 100, max_frames = 200, history_frames = 40;
  bool in_process = false;  // --bag: time the stages in this process instead of through the nodelets
  bool no_markers = false;
  NodeletBenchOptions nodelets;  // --bag through the nodelets: the options only that run has
};

// One input frame: the scan and the ego motion from the previous one (identity when unknown).
struct BenchFrame {
  PointCloud cloud;
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();  // sensor -> fixed
  bool follows = false;                                    // the previous entry is the previous sweep
};

std::vector<BenchFrame> framesFromData(const BenchArgs& a) {
  std::vector<BenchFrame> out;
  auto binsIn = [](const fs::path& dir) {
    std::vector<std::string> bins;
    if (fs::is_directory(dir))
      for (const auto& e : fs::directory_iterator(dir))
        if (e.is_regular_file() && e.path().extension() == ".bin") bins.push_back(e.path().string());
    std::sort(bins.begin(), bins.end());
    return bins;
  };
  // A folder of scans (e.g. ../shared/data/unlabeled_scans), or the object layout: consecutive files are not
  // necessarily consecutive sweeps, but the 22 unlabeled scans are; the motion between them is unknown (identity).
  for (const fs::path& dir : {fs::path(a.data), fs::path(a.data) / "velodyne", fs::path(a.data) / "training" / "velodyne"}) {
    const auto bins = binsIn(dir);
    if (bins.empty()) continue;
    for (const std::string& b : bins) {
      if (static_cast<int>(out.size()) >= a.max_frames) break;
      out.push_back({kitti::readVelodyne(b), Eigen::Isometry3d::Identity(), !out.empty()});
    }
    return out;
  }
  kitti::TrackingDataset ds(a.data);
  const auto seqs = ds.sequences();
  if (seqs.empty()) throw std::runtime_error(a.data + ": no scans (a folder of .bin files or a KITTI layout expected)");
  const std::string seq = a.sequence.empty() ? seqs.front() : a.sequence;
  io::forEachSweep(ds, seq, [&](const io::Sweep& s) {
    if (static_cast<int>(out.size()) < a.max_frames) out.push_back({*s.cloud, s.pose, s.previous != nullptr});
  });
  return out;
}

std::vector<BenchFrame> framesFromBag(const BenchArgs& a) {
  rosbag::Bag bag(a.bag, rosbag::bagmode::Read);
  std::string topic = a.topic;
  if (topic.empty()) {
    rosbag::View all(bag);
    for (const rosbag::ConnectionInfo* c : all.getConnections())
      if (c->datatype == "sensor_msgs/PointCloud2") {
        topic = c->topic;
        break;
      }
    if (topic.empty()) throw std::runtime_error(a.bag + ": no sensor_msgs/PointCloud2 topic");
  }
  std::vector<BenchFrame> out;
  rosbag::View view(bag, rosbag::TopicQuery(topic));
  for (const rosbag::MessageInstance& m : view) {
    if (static_cast<int>(out.size()) >= a.max_frames) break;
    const auto msg = m.instantiate<sensor_msgs::PointCloud2>();
    if (!msg) continue;
    out.push_back({ret3d::toCloud(*msg), Eigen::Isometry3d::Identity(), !out.empty()});
  }
  if (out.empty()) throw std::runtime_error(a.bag + ": no PointCloud2 messages on " + topic);
  std::cout << "bench: " << out.size() << " clouds from " << a.bag << " " << topic
            << " (ego motion taken as zero: the timing does not depend on it)\n";
  return out;
}

// A synthetic frame of n objects over sx x sy metres in front of the sensor: KITTI-like when spread over 70 x 80 m,
// pessimistic (many edges) when crowded into 30 x 30 m.
Detections layout(int n, double sx, double sy, std::mt19937& rng) {
  std::uniform_real_distribution<double> u(0, 1);
  Detections d;
  for (int i = 0; i < n; ++i) {
    Box b;
    b.label = kDetectedClasses[static_cast<std::size_t>(i % 3)];
    b.length = b.label == ObjectClass::Car ? 3.9 : b.label == ObjectClass::Pedestrian ? 0.8 : 1.8;
    b.width = b.label == ObjectClass::Car ? 1.6 : 0.6;
    b.height = b.label == ObjectClass::Car ? 1.5 : 1.7;
    b.x = sx * u(rng);
    b.y = sy * (u(rng) - 0.5);
    b.z = -0.9;
    b.yaw = M_PI * (2 * u(rng) - 1);
    b.score = static_cast<float>(u(rng));
    d.boxes.push_back(b);
  }
  return d;
}

struct Summary {
  double median = 0, p95 = 0;
};

Summary summarise(std::vector<double> v) {
  Summary s;
  if (v.empty()) return s;
  std::sort(v.begin(), v.end());
  s.median = v.size() % 2 ? v[v.size() / 2] : 0.5 * (v[v.size() / 2 - 1] + v[v.size() / 2]);
  s.p95 = v[std::min(v.size() - 1, static_cast<std::size_t>(std::ceil(0.95 * v.size())) - 1)];
  return s;
}

void printRow(const std::string& name, const Summary& s, std::ostringstream* json, bool* first) {
  std::cout << std::left << std::setw(26) << name << std::right << std::fixed << std::setprecision(3) << std::setw(12)
            << s.median << std::setw(12) << s.p95 << "\n";
  *json << (*first ? "" : ", ") << "\"" << name << "\": {\"median_ms\": " << s.median << ", \"p95_ms\": " << s.p95
        << "}";
  *first = false;
}

void writeJson(const std::string& path, const std::string& text) {
  if (path.empty()) return;
  if (fs::path(path).has_parent_path()) fs::create_directories(fs::path(path).parent_path());
  std::ofstream(path) << text;
  std::cout << "bench: wrote " << path << "\n";
}

// Without the base stage: the relation stages and the tracker per frame on synthetic frames of --objects objects
// (the graph and the tracks are built inside), so their cost is known for crowded scenes no drive provides. The
// objects move at constant velocity, so tracks persist and their histories fill up (warm-up: at least the history
// length, in frames).
int benchSynthetic(const BenchArgs& a) {
  OfflinePipeline p(a.pipeline);
  std::cout << "bench: " << p.describe() << "; " << a.pipeline.threads << " threads, " << a.warmup
            << " warm-up and " << a.min_runs << " timed frames per case\n";
  std::cout << std::left << std::setw(26) << "case" << std::right << std::setw(12) << "median ms" << std::setw(12)
            << "p95 ms" << "\n";
  std::ostringstream json;
  json << "{";
  bool first = true;
  std::mt19937 rng(1);
  std::uniform_real_distribution<double> speed(-1.0, 1.0);
  const Eigen::Isometry3d I = Eigen::Isometry3d::Identity();
  std::stringstream ss(a.objects);
  std::string item;
  int cases = 0;
  while (std::getline(ss, item, ',')) {
    const int n = std::stoi(item);
    for (const bool crowded : {false, true}) {
      Detections d = crowded ? layout(n, 30, 30, rng) : layout(n, 70, 80, rng);
      for (Box& b : d.boxes) {
        const double v = b.label == ObjectClass::Car ? 10 : b.label == ObjectClass::Cyclist ? 5 : 1.5;
        b.vx = v * speed(rng), b.vy = v * speed(rng);
      }
      // An IntraRM trained on detector features gets random ones of its length (the cost does not depend on them).
      d.feature_dim = p.intraFeatureDim();
      std::normal_distribution<float> feature(0.0f, 1.0f);
      d.features.resize(d.boxes.size() * d.feature_dim);
      for (float& x : d.features) x = feature(rng);
      p.reset();
      ++cases;
      // Warm-up frames fill the track histories first (the cost grows with their length).
      const int warm = std::max(a.warmup, p.tracks() ? std::max(a.history_frames, p.historyLength()) : 0);
      for (int k = 0; k < warm + a.min_runs; ++k) {
        if (k == warm) p.clearTimes();
        Detections f = d;
        for (Box& b : f.boxes) b.x += 0.1 * k * b.vx, b.y += 0.1 * k * b.vy;
        p.run(nullptr, nullptr, I, std::move(f), 1000.0 * cases + 0.1 * k, I);  // each case later than the last
      }
      const std::string name = std::to_string(n) + (crowded ? "_crowded" : "_spread");
      for (const char* stage : {"intra", "track", "inter", "total"})
        if (p.times().all().count(stage)) printRow(std::string(stage) + "_" + name, summarise(p.times().all().at(stage)),
                                                   &json, &first);
    }
  }
  json << "}\n";
  writeJson(a.json, json.str());
  return 0;
}

// The model file a stage runs with: the explicit file, else <--models>/<name>, else the package's default (as
// launch/ret3d.launch); checked here so that a wrong path stops the bench before any process starts.
std::string nodeletModel(const std::string& explicit_path, const std::string& models, const std::string& name,
                         const std::string& option) {
  const std::string path = !explicit_path.empty() ? explicit_path
                           : models.empty()       ? defaultModelPath(name)
                                                  : (fs::path(models) / name).string();
  if (!fs::is_regular_file(path))
    throw std::runtime_error(path + ": no such model file (give --models DIR with " + name + ", or " + option + ")");
  return path;
}

int benchNodelets(const BenchArgs& a) {
  NodeletBenchOptions o = a.nodelets;
  const PipelineConfig& p = a.pipeline;
  auto has = [&](const char* s) { return std::find(p.stages.begin(), p.stages.end(), s) != p.stages.end(); };
  o.bag = a.bag;
  o.topic = a.topic;
  o.stages = p.stages;
  o.detector_model = nodeletModel(p.detector_model, p.models, "detector.pt", "--detector-model FILE");
  if (has("intra")) o.intra_model = nodeletModel(p.intra_model, p.models, "intra_rm.pt", "--intra-model FILE");
  if (has("inter")) o.inter_model = nodeletModel(p.inter_model, p.models, "inter_rm.pt", "--inter-model FILE");
  o.detector_config = p.detector_config;
  o.tracker_config = p.tracker_config;
  o.score_threshold = p.score_threshold;
  o.grid_extent = p.grid_extent;
  o.threads = p.threads;
  o.warmup = a.warmup;
  o.max_frames = a.max_frames;
  o.json = a.json;
  o.markers = !a.no_markers;
  return runNodeletBench(o);
}

int runBench(BenchArgs a) {
  a.pipeline.stages = parseStages(a.stages);
  if (!a.bag.empty() && a.data.empty() && !a.in_process) return benchNodelets(a);
  if (!a.pipeline.stages.empty() && a.pipeline.stages.front() != "base" && a.data.empty() && a.bag.empty())
    return benchSynthetic(a);
  if (a.data.empty() == a.bag.empty()) throw std::runtime_error("give exactly one of --data DIR and --bag FILE");
  if (a.pipeline.stages.empty() || a.pipeline.stages.front() != "base")
    throw std::runtime_error("--stages must start with base on point clouds (--data, --bag); without base, give "
                             "neither: the later stages are timed on synthetic frames of --objects objects");
  const std::vector<BenchFrame> frames = a.bag.empty() ? framesFromData(a) : framesFromBag(a);
  if (frames.empty()) throw std::runtime_error("no frames to time");
  OfflinePipeline p(a.pipeline);
  std::size_t points = 0;
  for (const BenchFrame& f : frames) points += f.cloud.size();
  std::cout << "bench: " << p.describe() << "\n"
            << "bench: " << frames.size() << " frames, " << points / frames.size() << " points per scan on average, "
            << a.pipeline.threads << " threads, " << a.warmup << " warm-up runs, at least " << a.min_runs
            << " timed runs; " << std::thread::hardware_concurrency() << " cores here\n";
  int runs = 0, pass = 0;
  std::size_t boxes = 0;
  while (runs < a.min_runs + a.warmup) {
    p.reset();
    for (std::size_t i = 0; i < frames.size() && runs < a.min_runs + a.warmup; ++i, ++runs) {
      if (runs == a.warmup) p.clearTimes();
      const BenchFrame& f = frames[i];
      const bool prev = i > 0 && f.follows;
      const Eigen::Isometry3d prev_to_current =
          prev ? Eigen::Isometry3d(f.pose.inverse() * frames[i - 1].pose) : Eigen::Isometry3d::Identity();
      // Each pass is a new stretch of time for the tracker.
      const double stamp = 0.1 * static_cast<double>(i) + 1000.0 * pass;
      const Detections d = p.run(&f.cloud, prev ? &frames[i - 1].cloud : nullptr, prev_to_current, {}, stamp, f.pose);
      if (runs >= a.warmup) boxes += d.size();
    }
    ++pass;
  }
  const auto& t = p.times().all();
  std::cout << std::left << std::setw(26) << "stage" << std::right << std::setw(12) << "median ms" << std::setw(12)
            << "p95 ms" << "\n";
  std::ostringstream json;
  json << "{";
  bool first = true;
  for (const char* stage : {"bev", "network", "decode", "nms", "refine", "intra", "track", "inter", "total"})
    if (t.count(stage)) printRow(stage, summarise(t.at(stage)), &json, &first);
  // The base detector alone (BEV + network + decoding + NMS + point refinement), the figure of the latency budget.
  std::vector<double> base;
  for (std::size_t i = 0; i < t.at("bev").size(); ++i)
    base.push_back(t.at("bev")[i] + t.at("network")[i] + t.at("decode")[i] + t.at("nms")[i] + t.at("refine")[i]);
  printRow("base", summarise(base), &json, &first);
  std::cout << "(base = bev + network + decode + nms + refine)\n";
  const Detector* det = p.detector();
  const std::string model = det->options().inference.model_path;
  std::cout << "detector: " << det->parameterCount() << " parameters, model file " << fs::file_size(model)
            << " bytes; " << static_cast<double>(boxes) / std::max(1, a.min_runs) << " boxes per frame\n";
  json << ", \"parameters\": " << det->parameterCount() << ", \"model_bytes\": " << fs::file_size(model)
       << ", \"frames\": " << frames.size() << ", \"runs\": " << a.min_runs << ", \"threads\": " << a.pipeline.threads
       << "}\n";
  writeJson(a.json, json.str());
  return 0;
}

CommandRegistrar reg("bench", "time the pipeline: through the nodelets on a bag, or each stage in-process (median and p95)",
                     [](CLI::App& app) -> CommandRun {
  auto a = std::make_shared<BenchArgs>();
  PipelineConfig& p = a->pipeline;
  app.add_option("--data", a->data, "scans: a folder of .bin files, a KITTI object or tracking folder");
  app.add_option("--sequence", a->sequence, "tracking layout: the sequence to time (default: the first)");
  app.add_option("--bag", a->bag, "a bag played through the real nodelets in one manager (with --in-process: its "
                                  "clouds timed stage by stage in this process)");
  app.add_flag("--in-process", a->in_process, "--bag: time each stage in this process, as with --data");
  NodeletBenchOptions& n = a->nodelets;
  app.add_option("--rate", n.rate, "--bag: playback speed factor (as rosbag play -r)")->capture_default_str();
  app.add_option("--params", n.params, "--bag: the nodelets' YAML (default: $(find ret3d)/config/ret3d.yaml)");
  app.add_option("--manager-threads", n.manager_threads, "--bag: the manager's callback threads")
      ->capture_default_str();
  app.add_option("--tail", n.tail, "--bag: s to wait after the last cloud for its outputs")->capture_default_str();
  app.add_flag("--no-markers", a->no_markers, "--bag: without the MarkerNodelet (the launch file loads it)");
  app.add_option("--topic", a->topic, "bag topic (default: the first PointCloud2 topic)");
  app.add_option("--models", p.models, "folder with detector.pt, intra_rm.pt, inter_rm.pt (e.g. models/lwd3d; "
                                 "--bag: that is the default, as in launch/ret3d.launch)");
  app.add_option("--detector-model", p.detector_model, "detector model file (overrides --models)");
  app.add_option("--intra-model", p.intra_model, "IntraRM model file (overrides --models)");
  app.add_option("--inter-model", p.inter_model, "InterRM model file (overrides --models)");
  app.add_option("--detector-config", p.detector_config, "detector YAML (default: the config in the model file)");
  app.add_option("--tracker-config", p.tracker_config,
                 "tracker YAML (default: config/tracker_lwd3d_pipeline.yaml with the base stage, as the "
                 "nodelets; without it config/tracker.yaml's values, built in; --bag: the one config/ret3d.yaml names)");
  app.add_option("--score-threshold", p.score_threshold, "detector score threshold (default: the model's; --bag: config/ret3d.yaml's)");
  addGridExtentOption(app, &p.grid_extent);
  app.add_option("--stages", a->stages, "comma-separated stages in order, starting with base")->capture_default_str();
  app.add_option("--threads", p.threads, "CPU threads for libtorch")->capture_default_str();
  app.add_option("--warmup", a->warmup, "untimed runs first (--bag: clouds left out of the statistics)")->capture_default_str();
  app.add_option("--min-runs", a->min_runs, "timed runs (frames are cycled)")->capture_default_str();
  app.add_option("--max-frames", a->max_frames, "frames read at most")->capture_default_str();
  app.add_option("--objects", a->objects, "without the base stage: object counts of the synthetic frames")
      ->capture_default_str();
  app.add_option("--json", a->json, "write {\"<stage>\": {\"median_ms\", \"p95_ms\"}, ..., \"total\": {...}} (--bag: "
                                    "..., \"end_to_end\": {...}, \"frames\", \"dropped\", \"cpu_cores\")");
  return [a]() { return runBench(*a); };
});

}  // namespace
}  // namespace tools
}  // namespace ret3d
