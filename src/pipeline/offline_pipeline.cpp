#include "ret3d/pipeline/offline_pipeline.h"

#include <algorithm>
#include <chrono>
#include <filesystem>
#include <map>
#include <sstream>
#include <stdexcept>

#include "ret3d/detector/model_file.h"
#include "ret3d/pipeline/score_threshold.h"
#include "ret3d/pipeline/stage_layout.h"
#include "ret3d/pipeline/tracker_default.h"
#include "ret3d/tracking/tracker_options.h"

namespace ret3d {
namespace pipeline {

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

// A relation module (IntraRM, InterRM) from its file, run with `threads`.
template <typename Module, typename Options>
std::unique_ptr<Module> loadModule(const std::string& path, int threads) {
  Options o;
  o.model_path = path;
  o.threads = threads;
  return std::make_unique<Module>(o);
}

bool has(const std::vector<std::string>& v, const std::string& s) { return std::find(v.begin(), v.end(), s) != v.end(); }

}  // namespace

std::vector<std::string> parseStages(const std::string& list) {
  // The stages in the order of the pipeline's layout (pipeline/stage_layout.h): base, intra, track, inter.
  static const std::vector<std::string> kOrder = offlineStageNames();
  std::string known, order;
  for (const std::string& s : kOrder) known += s + ", ", order += (order.empty() ? "" : ", ") + s;
  std::vector<std::string> out;
  std::stringstream ss(list);
  std::string item;
  while (std::getline(ss, item, ',')) {
    if (item.empty() || item == "none") continue;
    const auto it = std::find(kOrder.begin(), kOrder.end(), item);
    if (it == kOrder.end())
      throw std::runtime_error("--stages: unknown stage '" + item + "' (known: " + known + "none)");
    if (!out.empty() && std::find(kOrder.begin(), kOrder.end(), out.back()) >= it)
      throw std::runtime_error("--stages: '" + item + "' after '" + out.back() +
                               "' (the order is " + order + ")");
    out.push_back(item);
  }
  if (has(out, "track") && has(out, "inter")) out.erase(std::find(out.begin(), out.end(), "track"));
  return out;
}

bool usesPackageDir(const PipelineConfig& c) {
  // The nodelets' tracker config and the threshold their detector feeds it from (params_score_threshold).
  return (c.tracker_config.empty() || c.score_threshold < 0) && has(c.stages, "base") &&
         (has(c.stages, "track") || has(c.stages, "inter"));
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
    // As the nodelets feed their tracker: pipeline/score_threshold.h says which source wins.
    const bool tracks = has(stages_, "track") || has(stages_, "inter");
    if (const std::optional<float> t =
            chooseScoreThreshold(c.params_score_threshold, tracks,
                                 c.score_threshold >= 0 ? std::optional<double>(c.score_threshold) : std::nullopt))
      o.inference.setScoreThreshold(*t);
    try {
      if (!c.grid_extent.empty()) o.inference.grid_extent = GridExtent::fromValues(c.grid_extent);
      o.validate();
    } catch (const OptionError& e) {
      // The command line's options by their names; other keys came with the model or --detector-config.
      const std::map<std::string, std::string> flags = {{"grid_extent", "--grid-extent"},
                                                        {"inference.grid_extent", "--grid-extent"},
                                                        {"inference.score_threshold", "--score-threshold"},
                                                        {"inference.threads", "--threads"}};
      const auto flag = flags.find(e.key());
      throw std::runtime_error(flag == flags.end() ? path + ": " + e.what()
                                                   : flag->second + ": " + e.value() + ": " + e.reason());
    }
    detector_ = std::make_unique<Detector>(o);
    desc << "; detector " << path << " (" << headTypeName(o.model.head) << " head, " << detector_->parameterCount()
         << " parameters, score >= " << o.inference.describeScoreThresholds() << ", grid " << detector_->describeGrids()
         << ")";
  }
  if (has(stages_, "intra")) {
    const std::string path =
        resolveModel(c.intra_model, c.models, "intra_rm.pt", "intra", "an IntraRM model", "--intra-model");
    intra_ = loadModule<relation::IntraRM, relation::IntraRMOptions>(path, c.threads);
    desc << "; IntraRM " << path;
  }
  if (has(stages_, "inter")) {
    const std::string path =
        resolveModel(c.inter_model, c.models, "inter_rm.pt", "inter", "an InterRM model", "--inter-model");
    inter_ = loadModule<relation::InterRM, relation::InterRMOptions>(path, c.threads);
    desc << "; InterRM " << path;
  }
  if (has(stages_, "track") || has(stages_, "inter")) {
    // Unset: the nodelets' config for the LWD-3D detector's probabilities; TrackerOptions' (PointRCNN) otherwise.
    const std::string config = !c.tracker_config.empty() ? c.tracker_config
                               : hasBase()              ? defaultTrackerConfig(stages_, c.package_dir)
                                                        : "";
    const TrackerOptions t = config.empty() ? TrackerOptions{} : loadTrackerOptions(config);
    tracking_ = std::make_unique<TrackRefiner>(t, inter_.get());
    history_length_ = inter_ ? static_cast<int>(tracking_->historyLength()) : t.history_length;
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

}  // namespace pipeline
}  // namespace ret3d
