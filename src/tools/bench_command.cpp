// `ret3d bench --data DIR|--bag FILE --models DIR [--stages LIST] [--json FILE]`: times the pipeline.
// --bag FILE: through the real nodelets in one manager (tools/nodelet_bench.h): the bag played at its rate from a
// player process, per-stage times and end-to-end latency (cloud stamp to /objects) p50 / p95, drops, CPU use.
// --data DIR (or --bag FILE --in-process): each stage called in this process over real frames, after a warm-up; the
// median and p95 per stage (the base detector split into BEV, network, decoding and NMS). Scans come from a KITTI
// tracking or object folder, a folder of .bin scans, or the PointCloud2 messages of a bag. Frames are cycled until
// --min-runs timed runs, so a short drive still gives a p95.
// Neither: the stages after the detector timed on synthetic frames of --objects objects.
// --loop-frames N (--bag): the soak, N clouds through the nodelets with memory, descriptors and latency sampled.
// --load N: N spinning processes meanwhile. --baseline DIR: another set of models timed in the same run, and the
// ratio new / baseline of the detector's median and p95.
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <iostream>
#include <optional>
#include <random>
#include <sstream>
#include <thread>

#include <rosbag/bag.h>
#include <rosbag/view.h>
#include <sensor_msgs/PointCloud2.h>

#include "ret3d/core/json_writer.h"
#include "ret3d/core/log.h"
#include "ret3d/core/stats.h"
#include "ret3d/io/kitti.h"
#include "ret3d/io/sweeps.h"
#include "ret3d/ros/bag_reader.h"
#include "ret3d/ros/conversions.h"
#include "ret3d/ros/params.h"
#include "tools/command.h"
#include "tools/nodelet_bench.h"
#include "tools/pipeline_options.h"

namespace ret3d {
namespace tools {
namespace {

namespace fs = std::filesystem;

struct BenchArgs {
  pipeline::PipelineConfig pipeline;
  std::string data, bag, topic, stages = "base,intra,track,inter", json, sequence, objects = "50,300";
  int warmup = 5, min_runs = 100, max_frames = 200, history_frames = 40;
  bool in_process = false;  // --bag: time the stages in this process instead of through the nodelets
  bool no_markers = false;
  NodeletBenchOptions nodelets;  // --bag through the nodelets: the options only that run has
  std::string baseline;          // a folder of models timed in the same run, for the new/baseline ratio
  std::string baseline_config;   // the baseline detector's YAML (empty: the config stored in its model file)
};

// The baseline's pipeline: the detector of `dir` with its own configuration (stored in the model file, or `config`)
// and its own grid; its IntraRM / InterRM where `dir` has them, else the same as the new pipeline's. Stage list,
// threads, score threshold and tracker config are the run's.
pipeline::PipelineConfig baselineConfig(const pipeline::PipelineConfig& p, const std::string& dir,
                                        const std::string& config) {
  if (!fs::is_directory(dir)) throw std::runtime_error("--baseline " + dir + ": no such folder");
  const fs::path detector = fs::path(dir) / "detector.pt";
  if (!fs::is_regular_file(detector))
    throw std::runtime_error("--baseline " + dir + ": no detector.pt there (a folder of models, e.g. models/lwd3d)");
  pipeline::PipelineConfig b = p;
  b.detector_model = detector.string();
  b.detector_config = config;
  b.grid_extent.clear();
  for (auto [name, file] : {std::pair{"intra_rm.pt", &b.intra_model}, std::pair{"inter_rm.pt", &b.inter_model}})
    if (fs::is_regular_file(fs::path(dir) / name)) *file = (fs::path(dir) / name).string();
  return b;
}

// "median 45.1 / 40.2 ms = 1.12x" for new and baseline figures.
std::string ratioText(const char* what, double now, double base) {
  std::ostringstream s;
  s << std::fixed << std::setprecision(1) << what << " " << now << " / " << base << " ms = " << std::setprecision(2)
    << (base > 0 ? now / base : 0.0) << "x";
  return s.str();
}

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
  rosbag::Bag bag;
  openCheckedBag(bag, a.bag);
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
    const auto msg = readBagMessage<sensor_msgs::PointCloud2>(m);
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
  s.median = median(v);
  s.p95 = nearestRankPercentile(std::move(v), 95);
  return s;
}

void printRow(const std::string& name, const Summary& s, JsonWriter* json) {
  std::cout << std::left << std::setw(26) << name << std::right << std::fixed << std::setprecision(3) << std::setw(12)
            << s.median << std::setw(12) << s.p95 << "\n";
  json->beginObject(name).field("median_ms", s.median).field("p95_ms", s.p95).endObject();
}

void writeJson(const std::string& path, const JsonWriter& json) {
  if (path.empty()) return;
  json.save(path);
  std::cout << "bench: wrote " << path << "\n";
}

// Without the base stage: the relation stages and the tracker per frame on synthetic frames of --objects objects
// (the graph and the tracks are built inside), so their cost is known for crowded scenes no drive provides. The
// objects move at constant velocity, so tracks persist and their histories fill up (warm-up: at least the history
// length, in frames).
int benchSynthetic(const BenchArgs& a) {
  if (!a.baseline.empty()) throw std::runtime_error("--baseline compares detectors: --stages must start with base");
  pipeline::OfflinePipeline p(withPackageDir(a.pipeline));
  const std::optional<BusyLoad> busy = a.nodelets.load > 0 ? std::make_optional<BusyLoad>(a.nodelets.load) : std::nullopt;
  std::cout << "bench: " << p.describe() << "; " << a.pipeline.threads << " threads, " << a.warmup
            << " warm-up and " << a.min_runs << " timed frames per case\n";
  std::cout << std::left << std::setw(26) << "case" << std::right << std::setw(12) << "median ms" << std::setw(12)
            << "p95 ms" << "\n";
  JsonWriter json;
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
        if (p.times().all().count(stage))
          printRow(std::string(stage) + "_" + name, summarise(p.times().all().at(stage)), &json);
    }
  }
  writeJson(a.json, json);
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

NodeletBenchOptions nodeletOptions(const BenchArgs& a, const pipeline::PipelineConfig& p) {
  NodeletBenchOptions o = a.nodelets;
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
  return o;
}

// The baseline through the nodelets in a child process (forked before this one starts ROS: a process runs one ROS
// node), then the new models in this one, one after the other on the same bag; the child's figures come back
// through a pipe.
int benchNodeletsAgainstBaseline(const BenchArgs& a) {
  const pipeline::PipelineConfig base_config = baselineConfig(a.pipeline, a.baseline, a.baseline_config);
  NodeletBenchOptions base = nodeletOptions(a, base_config);
  NodeletBenchOptions now = nodeletOptions(a, a.pipeline);
  if (!now.json.empty()) base.json = (fs::path(now.json).parent_path() / fs::path(now.json).stem()).string() +
                                     ".baseline" + fs::path(now.json).extension().string();
  int fds[2];
  if (pipe(fds) != 0) throw std::runtime_error(std::string("pipe: ") + std::strerror(errno));
  std::cout << "bench: 1/2 the baseline models (" << base.detector_model << ")" << std::endl;
  const pid_t pid = fork();
  if (pid < 0) throw std::runtime_error(std::string("fork: ") + std::strerror(errno));
  if (pid == 0) {
    close(fds[0]);
    int rc = 1;
    try {
      NodeletBenchResult r;
      rc = runNodeletBench(base, &r);
      std::ostringstream text;
      text << std::setprecision(17) << r.base_p50 << " " << r.base_p95 << " " << r.base_processing_p50 << " "
           << r.base_processing_p95 << " " << r.end_to_end_p50 << " " << r.end_to_end_p95 << "\n";
      const std::string t = text.str();
      if (write(fds[1], t.data(), t.size()) != static_cast<ssize_t>(t.size())) rc = 1;
    } catch (const std::exception& e) {
      std::cerr << "bench: the baseline run: " << e.what() << std::endl;
    }
    std::cout.flush();
    _exit(rc);
  }
  close(fds[1]);
  std::string text;
  char buffer[256];
  for (ssize_t n; (n = read(fds[0], buffer, sizeof(buffer))) > 0;) text.append(buffer, static_cast<std::size_t>(n));
  close(fds[0]);
  int status = 0;
  waitpid(pid, &status, 0);
  NodeletBenchResult b;
  std::istringstream in(text);
  in >> b.base_p50 >> b.base_p95 >> b.base_processing_p50 >> b.base_processing_p95 >> b.end_to_end_p50 >>
      b.end_to_end_p95;
  if (!WIFEXITED(status) || WEXITSTATUS(status) != 0 || !in)
    throw std::runtime_error("the baseline run failed (see its message above); the new models were not timed");

  std::cout << "bench: 2/2 the new models (" << now.detector_model << ")" << std::endl;
  NodeletBenchResult n;
  const int rc = runNodeletBench(now, &n);
  std::cout << "bench: new / baseline, one run after the other on this bag:\n"
            << "  " << ratioText("detector (/points to /detections) median", n.base_p50, b.base_p50) << ", "
            << ratioText("p95", n.base_p95, b.base_p95) << "\n";
  if (n.base_processing_p50 >= 0 && b.base_processing_p50 >= 0)
    std::cout << "  " << ratioText("detector processing (its /diagnostics) median", n.base_processing_p50,
                                   b.base_processing_p50)
              << ", " << ratioText("p95", n.base_processing_p95, b.base_processing_p95) << "\n";
  std::cout << "  " << ratioText("end-to-end median", n.end_to_end_p50, b.end_to_end_p50) << ", "
            << ratioText("p95", n.end_to_end_p95, b.end_to_end_p95) << "\n";
  return rc;
}

int benchNodelets(const BenchArgs& a) {
  if (!a.baseline.empty()) {
    if (a.nodelets.loop_frames > 0) throw std::runtime_error("--baseline and --loop-frames: give one of them");
    return benchNodeletsAgainstBaseline(a);
  }
  return runNodeletBench(nodeletOptions(a, a.pipeline));
}

// The base detector per frame (BEV + network + decoding + NMS + point refinement), the figure of the latency budget.
std::vector<double> baseTimes(const pipeline::OfflinePipeline& p) {
  const auto& t = p.times().all();
  std::vector<double> base;
  for (std::size_t i = 0; i < t.at("bev").size(); ++i)
    base.push_back(t.at("bev")[i] + t.at("network")[i] + t.at("decode")[i] + t.at("nms")[i] + t.at("refine")[i]);
  return base;
}

// The timed runs: frames in order (then again, each pass a new stretch of time for the tracker) until warm-up plus
// min_runs frames have run, the baseline interleaved frame by frame so a busy spell of the shared machine falls on
// both alike. Returns the boxes of the timed runs.
std::size_t timeFrames(const BenchArgs& a, const std::vector<BenchFrame>& frames, pipeline::OfflinePipeline& p,
                       std::optional<pipeline::OfflinePipeline>& baseline) {
  int runs = 0, pass = 0;
  std::size_t boxes = 0;
  while (runs < a.min_runs + a.warmup) {
    p.reset();
    if (baseline) baseline->reset();
    for (std::size_t i = 0; i < frames.size() && runs < a.min_runs + a.warmup; ++i, ++runs) {
      if (runs == a.warmup) p.clearTimes();
      if (runs == a.warmup && baseline) baseline->clearTimes();
      const BenchFrame& f = frames[i];
      const bool prev = i > 0 && f.follows;
      const Eigen::Isometry3d prev_to_current =
          prev ? Eigen::Isometry3d(f.pose.inverse() * frames[i - 1].pose) : Eigen::Isometry3d::Identity();
      const double stamp = 0.1 * static_cast<double>(i) + 1000.0 * pass;
      const Detections d = p.run(&f.cloud, prev ? &frames[i - 1].cloud : nullptr, prev_to_current, {}, stamp, f.pose);
      if (runs >= a.warmup) boxes += d.size();
      if (baseline) baseline->run(&f.cloud, prev ? &frames[i - 1].cloud : nullptr, prev_to_current, {}, stamp, f.pose);
    }
    ++pass;
  }
  return boxes;
}

int runBench(BenchArgs a) {
  a.pipeline.stages = pipeline::parseStages(a.stages);
  if (a.nodelets.load < 0) throw std::runtime_error("--load must be >= 0, not " + std::to_string(a.nodelets.load));
  const bool nodelets = !a.bag.empty() && a.data.empty() && !a.in_process;
  if (a.nodelets.loop_frames != 0 && !nodelets)
    throw std::runtime_error("--loop-frames (the soak) plays a bag through the nodelets: give --bag FILE without "
                             "--in-process or --data");
  if (nodelets) return benchNodelets(a);
  if (!a.pipeline.stages.empty() && a.pipeline.stages.front() != "base" && a.data.empty() && a.bag.empty())
    return benchSynthetic(a);
  if (a.data.empty() == a.bag.empty()) throw std::runtime_error("give exactly one of --data DIR and --bag FILE");
  if (a.pipeline.stages.empty() || a.pipeline.stages.front() != "base")
    throw std::runtime_error("--stages must start with base on point clouds (--data, --bag); without base, give "
                             "neither: the later stages are timed on synthetic frames of --objects objects");
  const std::vector<BenchFrame> frames = a.bag.empty() ? framesFromData(a) : framesFromBag(a);
  if (frames.empty()) throw std::runtime_error("no frames to time");
  pipeline::OfflinePipeline p(withPackageDir(a.pipeline));
  std::optional<pipeline::OfflinePipeline> baseline;
  if (!a.baseline.empty()) baseline.emplace(withPackageDir(baselineConfig(a.pipeline, a.baseline, a.baseline_config)));
  std::size_t points = 0;
  for (const BenchFrame& f : frames) points += f.cloud.size();
  std::cout << "bench: " << p.describe() << "\n";
  if (baseline) std::cout << "bench: baseline, run on each frame right after the new pipeline: " << baseline->describe()
                          << "\n";
  std::cout
            << "bench: " << frames.size() << " frames, " << points / frames.size() << " points per scan on average, "
            << a.pipeline.threads << " threads, " << a.warmup << " warm-up runs, at least " << a.min_runs
            << " timed runs; " << std::thread::hardware_concurrency() << " cores here\n";
  const std::optional<BusyLoad> busy = a.nodelets.load > 0 ? std::make_optional<BusyLoad>(a.nodelets.load) : std::nullopt;
  if (busy) std::cout << "bench: " << a.nodelets.load << " busy processes spinning (--load)\n";
  const std::size_t boxes = timeFrames(a, frames, p, baseline);
  const auto& t = p.times().all();
  std::cout << std::left << std::setw(26) << "stage" << std::right << std::setw(12) << "median ms" << std::setw(12)
            << "p95 ms" << "\n";
  JsonWriter json;
  for (const char* stage : {"bev", "network", "decode", "nms", "refine", "intra", "track", "inter", "total"})
    if (t.count(stage)) printRow(stage, summarise(t.at(stage)), &json);
  const Summary base = summarise(baseTimes(p));
  printRow("base", base, &json);
  std::cout << "(base = bev + network + decode + nms + refine)\n";
  if (baseline) {
    const auto& bt = baseline->times().all();
    for (const char* stage : {"network", "total"})
      if (bt.count(stage)) printRow(std::string("baseline_") + stage, summarise(bt.at(stage)), &json);
    const Summary b = summarise(baseTimes(*baseline));
    printRow("baseline_base", b, &json);
    std::cout << "bench: new / baseline, interleaved frame by frame: "
              << ratioText("detector (base) median", base.median, b.median) << ", " << ratioText("p95", base.p95, b.p95)
              << "\n";
    json.field("base_ratio_median", b.median > 0 ? base.median / b.median : 0.0)
        .field("base_ratio_p95", b.p95 > 0 ? base.p95 / b.p95 : 0.0);
  }
  const Detector* det = p.detector();
  const std::string model = det->options().inference.model_path;
  std::cout << "detector: " << det->parameterCount() << " parameters, model file " << fs::file_size(model)
            << " bytes; " << static_cast<double>(boxes) / std::max(1, a.min_runs) << " boxes per frame\n";
  json.field("parameters", det->parameterCount())
      .field("model_bytes", fs::file_size(model))
      .field("frames", frames.size())
      .field("runs", a.min_runs)
      .field("threads", a.pipeline.threads);
  writeJson(a.json, json);
  return 0;
}

CommandRegistrar reg("bench", "time the pipeline: through the nodelets on a bag, or each stage in-process (median and p95)",
                     [](CLI::App& app) -> CommandRun {
  auto a = std::make_shared<BenchArgs>();
  pipeline::PipelineConfig& p = a->pipeline;
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
  app.add_option("--loop-frames", n.loop_frames,
                 "--bag: the soak: the bag played in a loop through the nodelets until N clouds have been played "
                 "(at the bag's rate); every --soak-every clouds this process's resident memory, open file "
                 "descriptors, threads and the latencies since the last sample are printed; at the end the checks "
                 "(memory from frame 1000 to the end < +5 %, same descriptor count, end-to-end p95 of the last 1000 "
                 "frames <= +10 % of the first 1000; a shorter run uses half its length). Writes --json (default "
                 "out/soak/soak.json) and a table for plots beside it (.tsv). Exit code 0 when the run completed, "
                 "whatever the checks say (scripts/soak.sh fails on them); 0: play once")
      ->capture_default_str();
  app.add_option("--soak-every", n.soak_every, "--loop-frames: clouds per sample")->capture_default_str();
  app.add_option("--load", n.load, "busy processes, one spinning per core, while timing (--bag: from the start of "
                                   "the replay to its end), for figures under a reproducible load")
      ->capture_default_str();
  app.add_option("--baseline", a->baseline,
                 "a folder of models (detector.pt; intra_rm.pt, inter_rm.pt when there, else the new ones) timed in "
                 "the same run, with its detector's own config and grid (--detector-config, --grid-extent apply to "
                 "the new models only); prints new/baseline of the detector's median and p95. --bag: the baseline "
                 "first in a child process, then the new models (its --json goes to <name>.baseline.json); --data, "
                 "--in-process: both pipelines on each frame in turn");
  app.add_option("--baseline-detector-config", a->baseline_config,
                 "--baseline: the baseline detector's YAML (default: the config stored in its model file)");
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
  app.add_option("--score-threshold", p.score_threshold, "the lowest score the detector publishes (default: with the track stage or --bag "
                 "config/ret3d.yaml's; otherwise the model's)");
  addGridExtentOption(app, &p.grid_extent);
  app.add_option("--stages", a->stages, "comma-separated stages in order, starting with base")->capture_default_str();
  app.add_option("--threads", p.threads, "CPU threads for libtorch")->capture_default_str();
  app.add_option("--warmup", a->warmup, "untimed runs first (--bag: clouds left out of the statistics)")->capture_default_str();
  app.add_option("--min-runs", a->min_runs, "timed runs (frames are cycled)")->capture_default_str();
  app.add_option("--max-frames", a->max_frames, "frames read at most (--loop-frames: clouds per pass of the bag)")->capture_default_str();
  app.add_option("--objects", a->objects, "without the base stage: object counts of the synthetic frames")
      ->capture_default_str();
  app.add_option("--json", a->json, "write {\"<stage>\": {\"median_ms\", \"p95_ms\"}, ..., \"total\": {...}} (--bag: "
                                    "..., \"end_to_end\": {...}, \"frames\", \"dropped\", \"cpu_cores\"; --loop-frames: "
                                    "{\"samples\": [...], \"checks\": {...}}, default out/soak/soak.json)");
  return [a]() {
    if (a->nodelets.loop_frames > 0 && a->json.empty()) a->json = "out/soak/soak.json";
    return runBench(*a);
  };
});

}  // namespace
}  // namespace tools
}  // namespace ret3d
