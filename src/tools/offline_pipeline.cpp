#include "tools/offline_pipeline.h"

#include <algorithm>
#include <chrono>
#include <filesystem>
#include <sstream>
#include <stdexcept>

#include <CLI/CLI.hpp>

#include "ret3d/detector/model_file.h"
#include "ret3d/ros/params.h"
#include "ret3d/tracking/tracker_options.h"
#include "tools/tracker_default.h"

namespace ret3d {
namespace tools {

namespace {

namespace fs = std::filesystem;

double msSince(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
}

// The explicit file, else <models>/<name> when it exists; throws naming both ways to give it when neither does.
std::string resolveModel(const std::string& explicit_path, const std::string& models, const std::string& name,
                         const std::string& stage, const std::string& what, const std::string& option) {
  if (!explicit_path.empty()) return explicit_path;
  const std::string p = models.empty() ? "" : (fs::path(models) / name).string();
  if (p.empty() || !fs::exists(p))
    throw std::runtime_error("--stages " + stage + " needs " + what + ": --models DIR with " + name + ", or " + option +
                             " FILE");
  return p;
}

bool has(const std::vector<std::string>& v, const std::string& s) { return std::find(v.begin(), v.end(), s) != v.end(); }

}  // namespace

std::vector<std::string> parseStages(const std::string& list) {
  static const std::vector<std::string> kOrder = {"base", "intra", "track", "inter"};
  std::vector<std::string> out;
  std::stringstream ss(list);
  std::string item;
  while (std::getline(ss, item, ',')) {
    if (item.empty() || item == "none") continue;
    const auto it = std::find(kOrder.begin(), kOrder.end(), item);
    if (it == kOrder.end())
      throw std::runtime_error("--stages: unknown stage '" + item + "' (known: base, intra, track, inter, none)");
    if (!out.empty() && std::find(kOrder.begin(), kOrder.end(), out.back()) >= it)
      throw std::runtime_error("--stages: '" + item + "' after '" + out.back() +
                               "' (the order is base, intra, track, inter)");
    out.push_back(item);
  }
  if (has(out, "track") && has(out, "inter")) out.erase(std::find(out.begin(), out.end(), "track"));
  return out;
}

void addGridExtentOption(CLI::App& app, std::vector<double>* extent) {
  app.add_option("--grid-extent", *extent,
                 "run the detector over this grid, x_min,x_max,y_min,y_max in m (e.g. --grid-extent=-80,80,-48,48; "
                 "default: the model's); the cost grows with the area")
      ->delimiter(',')
      ->expected(4);
}

OfflinePipeline::OfflinePipeline(const PipelineConfig& c) : stages_(c.stages) {
  std::ostringstream desc;
  desc << "stages";
  for (const std::string& s : stages_) desc << " " << s;
  if (stages_.empty()) desc << " none";
  if (has(stages_, "base")) {
    const std::string path =
        resolveModel(c.detector_model, c.models, "detector.pt", "base", "a detector model", "--detector-model");
    DetectorOptions o = detectorOptionsForModel(path, c.detector_config);
    o.inference.threads = c.threads;
    if (c.score_threshold >= 0) {
      o.inference.score_threshold = c.score_threshold;
    } else if (has(stages_, "track") || has(stages_, "inter")) {  // as the nodelets feed their tracker
      o.inference.score_threshold =
          static_cast<float>(pipelineDetectorThreshold(packagePath(), o.inference.score_threshold));
    }
    if (!c.grid_extent.empty()) {
      o.inference.grid_extent = c.grid_extent;
      try {
        o.validateGridExtent();
      } catch (const std::invalid_argument& e) {
        throw std::runtime_error(std::string("--grid-extent: ") + e.what());
      }
    }
    detector_ = std::make_unique<Detector>(o);
    desc << "; detector " << path << " (" << headTypeName(o.model.head) << " head, " << detector_->parameterCount()
         << " parameters, score >= " << o.inference.score_threshold << ", grid " << o.inferenceGeometry().describe() << ")";
  }
  if (has(stages_, "intra")) {
    relation::IntraRMOptions o;
    o.model_path = resolveModel(c.intra_model, c.models, "intra_rm.pt", "intra", "an IntraRM model", "--intra-model");
    o.threads = c.threads;
    intra_ = std::make_unique<relation::IntraRM>(o);
    desc << "; IntraRM " << o.model_path;
  }
  if (has(stages_, "inter")) {
    relation::InterRMOptions o;
    o.model_path = resolveModel(c.inter_model, c.models, "inter_rm.pt", "inter", "an InterRM model", "--inter-model");
    o.threads = c.threads;
    inter_ = std::make_unique<relation::InterRM>(o);
    desc << "; InterRM " << o.model_path;
  }
  if (has(stages_, "track") || has(stages_, "inter")) {
    // Unset: the nodelets' config for the LWD-3D detector's probabilities; TrackerOptions' (PointRCNN) otherwise.
    // (packagePath() asks rospack, which complains on stderr without the package: only when needed.)
    const std::string config = !c.tracker_config.empty() ? c.tracker_config
                               : hasBase()              ? defaultTrackerConfig(stages_, packagePath())
                                                        : "";
    TrackerOptions t = config.empty() ? TrackerOptions{} : loadTrackerOptions(config);
    // As in the ROS pipeline (the InterRM nodelet keeps max_history boxes per track), the history InterRM sees is
    // its model's max_history, whatever the tracker config says.
    if (inter_) t.history_length = inter_->arch().max_history;
    history_length_ = t.history_length;
    tracking_ = std::make_unique<train::TrackingRefiner>(t, inter_.get());
    desc << "; tracker " << (config.empty() ? "built-in defaults (config/tracker.yaml's values)" : config);
    if (c.tracker_config.empty()) desc << (config.empty() ? ", for external detections" : ", the base stage's default");
  }
  description_ = desc.str();
}

OfflinePipeline::~OfflinePipeline() = default;

std::string OfflinePipeline::describe() const { return description_; }

std::size_t OfflinePipeline::intraFeatureDim() const { return intra_ ? intra_->arch().feature_dim : 0; }

void OfflinePipeline::reset() {
  if (tracking_) tracking_->reset();
}

Detections OfflinePipeline::run(const PointCloud* current, const PointCloud* previous,
                                const Eigen::Isometry3d& prev_to_current, Detections input, double stamp,
                                const Eigen::Isometry3d& sensor_to_fixed) {
  double total = 0;
  Detections d = std::move(input);
  if (detector_) {
    if (!current) throw std::logic_error("OfflinePipeline::run: the base stage needs a point cloud");
    d = detector_->detect(*current, previous, prev_to_current);
    const DetectorTimings& t = detector_->lastTimings();
    times_.add("bev", t.bev_ms);
    times_.add("network", t.network_ms);
    times_.add("decode", t.decode_ms);
    times_.add("nms", t.nms_ms);
    times_.add("refine", t.refine_ms);
    total += t.total();
  }
  if (intra_) {
    const auto t0 = std::chrono::steady_clock::now();
    d = intra_->refine(d);
    const double ms = msSince(t0);
    times_.add("intra", ms);
    total += ms;
  }
  if (tracking_) {
    const double track0 = tracking_->trackerSeconds(), inter0 = tracking_->interSeconds();
    d.boxes = tracking_->update(d.boxes, stamp, sensor_to_fixed);
    d.features.clear(), d.feature_dim = 0;  // the refined boxes are per track now
    const double track_ms = 1000.0 * (tracking_->trackerSeconds() - track0);
    times_.add("track", track_ms);
    total += track_ms;
    if (inter_) {
      const double inter_ms = 1000.0 * (tracking_->interSeconds() - inter0);
      times_.add("inter", inter_ms);
      total += inter_ms;
    }
  }
  times_.add("total", total);
  return d;
}

}  // namespace tools
}  // namespace ret3d
