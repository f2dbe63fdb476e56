// `ret3d eval --gt DIR_OR_BAG --pred DIR_OR_BAG --out REPORT_DIR [--metric kitti,waymo,mot] [--sequences LIST]
// [--classes LIST]`: KITTI AP (official devkit rules), Waymo-style AP/APH and tracking metrics, written as
// metrics.json, report.md and PNG plots, with the headline table on stdout.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <iostream>
#include <memory>
#include <optional>
#include <set>
#include <sstream>

#include "ret3d/core/log.h"
#include "ret3d/core/progress.h"
#include "ret3d/eval/eval_data.h"
#include "ret3d/eval/kitti_ap.h"
#include "ret3d/eval/mot_metrics.h"
#include "ret3d/eval/report.h"
#include "ret3d/eval/waymo_ap.h"
#include "ret3d/ros/bag_objects.h"
#include "tools/command.h"

namespace ret3d {
namespace tools {
namespace {

namespace fs = std::filesystem;
using namespace ret3d::eval;

struct EvalArgs {
  std::string gt, pred, out;
  std::string metrics = "kitti,waymo,mot";
  std::string sequences, classes = "Car,Pedestrian,Cyclist";
  std::string gt_format = "auto";
  std::string gt_topic = "/ground_truth/objects", pred_topic = "/objects";
  std::string calib;
  double bag_rate = 10.0, bag_start_time = 1.0e9, stamp_tolerance = 1e-3;
  std::string mot_similarity = "iou3d";
  double mot_threshold = 0.5, mot_zero_distance = 2.0, mot_max_range = 0;
  std::string kitti_recall = "devkit";
  int min_points = 0;
  int threads = 2;
};

std::vector<std::string> splitList(const std::string& s) {
  std::vector<std::string> out;
  std::stringstream ss(s);
  std::string item;
  while (std::getline(ss, item, ',')) {
    item.erase(0, item.find_first_not_of(" \t"));
    item.erase(item.find_last_not_of(" \t") + 1);
    if (!item.empty()) out.push_back(item);
  }
  return out;
}

bool isBag(const std::string& p) { return fs::is_regular_file(p) && fs::path(p).extension() == ".bag"; }

std::string detectGtFormat(const std::string& gt) {
  if (isBag(gt)) return "bag";
  for (const char* sub : {"", "training"}) {
    if (fs::is_directory(fs::path(gt) / sub / "label_02")) return "tracking";
    if (fs::is_directory(fs::path(gt) / sub / "label_2")) return "object";
  }
  throw std::runtime_error(gt + ": neither a bag nor a KITTI folder with label_02/ (tracking) or label_2/ (object)");
}

// A progress bar per stage, created on the first report.
std::function<void(std::size_t, std::size_t)> stageBar(std::optional<ProgressBar>& bar, const std::string& label) {
  return [&bar, label](std::size_t done, std::size_t total) {
    if (!bar) bar.emplace(label, total);
    bar->tick();
    if (done >= total) bar->finish();
  };
}

// Messages of a prediction bag, matched to frames by stamp (within the tolerance).
std::size_t attachBagPredictions(EvalData& data, const std::vector<StampedObjects>& msgs, double tolerance) {
  std::size_t matched = 0;
  for (const auto& m : msgs) {
    auto it = std::lower_bound(data.frames.begin(), data.frames.end(), m.stamp - tolerance,
                               [](const EvalFrame& f, double s) { return f.stamp < s; });
    if (it == data.frames.end() || std::abs(it->stamp - m.stamp) > tolerance) continue;
    it->pred_boxes.insert(it->pred_boxes.end(), m.boxes.begin(), m.boxes.end());
    ++matched;
  }
  return matched;
}

EvalData loadGroundTruthBag(const EvalArgs& a) {
  EvalData data;
  for (const auto& m : readBagObjects(a.gt, a.gt_topic)) {
    EvalFrame f;
    f.frame = static_cast<int>(data.frames.size());
    f.stamp = m.stamp;
    f.gt_boxes = m.boxes;
    f.gt_ignore.assign(f.gt_boxes.size(), 0);
    for (const Box& b : m.boxes) {
      if (b.num_points > 0) data.gt_has_point_counts = true;
      if (b.track_id > 0) data.gt_has_track_ids = true;
    }
    data.frames.push_back(std::move(f));
  }
  std::stable_sort(data.frames.begin(), data.frames.end(),
                   [](const EvalFrame& x, const EvalFrame& y) { return x.stamp < y.stamp; });
  data.gt_description = a.gt + " (bag, " + a.gt_topic + ")";
  return data;
}

// Ground truth, and the predictions when they are a folder (a prediction bag is attached afterwards).
EvalData loadData(const EvalArgs& a, const std::string& gt_format, bool pred_bag,
                  const std::vector<std::string>& sequences) {
  if (gt_format == "bag") {
    if (!pred_bag) throw std::invalid_argument("--gt is a bag: --pred must be a bag too (topic --pred-topic)");
    return loadGroundTruthBag(a);
  }
  if (gt_format == "tracking") return loadKittiTracking(a.gt, pred_bag ? "" : a.pred, sequences);
  if (gt_format == "object") {
    if (pred_bag) throw std::invalid_argument("a prediction bag needs ground truth from a bag or a tracking folder");
    return loadKittiObject(a.gt, a.pred);
  }
  throw std::invalid_argument("--gt-format: auto, object, tracking or bag");
}

// A tracking folder's single sequence; stamps are START + frame / RATE (as `ret3d convert` writes them).
std::size_t attachBagPredictionsByFrame(const EvalArgs& a, const std::vector<StampedObjects>& msgs, EvalData& data,
                                        EvalReport* report) {
  if (data.calibrations.size() != 1) {
    throw std::invalid_argument("a prediction bag with a tracking folder needs exactly one --sequences entry");
  }
  std::size_t matched = 0;
  const kitti::Calibration& calib = data.calibrations.begin()->second;
  for (const auto& m : msgs) {
    const double f = (m.stamp - a.bag_start_time) * a.bag_rate;
    const long idx = std::lround(f);
    if (std::abs(f - idx) * (1.0 / a.bag_rate) > a.stamp_tolerance || idx < 0 ||
        idx >= static_cast<long>(data.frames.size())) {
      continue;
    }
    EvalFrame& fr = data.frames[idx];
    fr.pred_boxes.insert(fr.pred_boxes.end(), m.boxes.begin(), m.boxes.end());
    ++matched;
  }
  for (auto& f : data.frames) f.pred_labels = boxesToCameraLabels(f.pred_boxes, calib);
  report->notes.push_back("Predictions from the bag were placed on frames by stamp = " +
                          std::to_string(a.bag_start_time) + " + frame / " + std::to_string(a.bag_rate) +
                          " and converted to camera labels with the sequence's calibration (front camera view).");
  return matched;
}

// Bag boxes are converted to camera labels with bag_calib when the ground truth is a bag too.
void attachPredictionBag(const EvalArgs& a, bool gt_bag, const kitti::Calibration& bag_calib, EvalData& data,
                         EvalReport* report) {
  const auto msgs = readBagObjects(a.pred, a.pred_topic);
  std::size_t matched = 0;
  if (gt_bag) {
    matched = attachBagPredictions(data, msgs, a.stamp_tolerance);
    for (auto& f : data.frames) fillLabelsFromBoxes(f, bag_calib);
    report->notes.push_back("Bag boxes (LiDAR frame) were converted to KITTI camera labels with " +
                            (a.calib.empty() ? std::string("the default KITTI calibration")
                                             : "the calibration " + a.calib) +
                            " and kept only in the front camera's view (in front of the camera, projected 2D box "
                            "overlapping the 1242x375 image). Bag ground truth has no truncation or occlusion, so "
                            "KITTI difficulty follows the 2D box height alone.");
  } else {
    matched = attachBagPredictionsByFrame(a, msgs, data, report);
  }
  for (const auto& f : data.frames) {
    for (const Box& b : f.pred_boxes) {
      if (b.track_id > 0) data.pred_has_track_ids = true;
    }
  }
  data.pred_description = a.pred + " (bag, " + a.pred_topic + ", " + std::to_string(msgs.size()) + " messages, " +
                          std::to_string(matched) + " matched to ground-truth frames)";
  if (matched < msgs.size()) {
    RET3D_WARN(msgs.size() - matched << " prediction messages match no ground-truth frame by stamp");
  }
}

MotSimilarity parseSimilarity(const std::string& name) {
  for (const MotSimilarity s : {MotSimilarity::Iou3d, MotSimilarity::IouBev, MotSimilarity::CenterDistance})
    if (name == similarityName(s)) return s;
  throw std::invalid_argument("--mot-similarity: iou3d, bev or center");
}

// Not inlined: inlined into runEval, GCC 12 warns (falsely) that MotOptions' default class list may be uninitialized.
[[gnu::noinline]] MotOptions motOptions(const EvalArgs& a, const std::vector<ObjectClass>& classes) {
  MotOptions o;
  o.classes = classes;
  o.threads = a.threads;
  o.threshold = a.mot_threshold;
  o.zero_distance = a.mot_zero_distance;
  o.max_range = a.mot_max_range;
  o.similarity = parseSimilarity(a.mot_similarity);
  return o;
}

// The metrics' results; EvalReport points into them.
struct EvalResults {
  KittiResult kitti_strict, kitti_loose;
  WaymoResult waymo;
  MotResult mot;
  IdStabilityResult id_stability;
};

void evalKitti(const EvalArgs& a, const std::vector<ObjectClass>& classes, const EvalData& data, EvalResults* res,
               EvalReport* report) {
  std::vector<KittiFrame> frames;
  frames.reserve(data.frames.size());
  for (const auto& f : data.frames) frames.push_back({f.gt_labels, f.pred_labels, f.gt_label_ignore});
  KittiApOptions o;
  o.classes = classes;
  o.exact_recall = a.kitti_recall == "exact";
  o.threads = a.threads;
  std::optional<ProgressBar> bar;
  o.progress = stageBar(bar, "KITTI AP");
  res->kitti_strict = evaluateKitti(frames, o);
  std::optional<ProgressBar> bar_loose;
  o.progress = stageBar(bar_loose, "KITTI AP (loose)");
  o.min_overlap = kKittiLooseOverlap;
  res->kitti_loose = evaluateKitti(frames, o);
  report->kitti = &res->kitti_strict;
  report->kitti_loose = &res->kitti_loose;
}

void evalWaymo(const EvalArgs& a, const std::vector<ObjectClass>& classes, EvalData& data, EvalResults* res,
               EvalReport* report) {
  if (!data.gt_has_point_counts) {
    std::optional<ProgressBar> bar;
    const std::size_t counted = countGroundTruthPoints(data, a.threads, stageBar(bar, "points in boxes"));
    if (counted > 0) report->notes.push_back("Waymo levels: points counted in each ground-truth box from the scans.");
  }
  WaymoOptions o;
  o.classes = classes;
  o.threads = a.threads;
  o.use_point_counts = data.gt_has_point_counts;
  std::optional<ProgressBar> bar;
  o.progress = stageBar(bar, "Waymo AP");
  res->waymo = evaluateWaymo(data.frames, o);
  report->waymo = &res->waymo;
  report->waymo_options = o;
  report->waymo_options.progress = nullptr;
}

void evalMot(const EvalArgs& a, const std::vector<ObjectClass>& classes, const EvalData& data, EvalResults* res,
             EvalReport* report) {
  if (!data.gt_has_track_ids || !data.pred_has_track_ids) {
    const std::string why = !data.gt_has_track_ids ? "the ground truth has no track ids"
                                                    : "the predictions have no track ids";
    RET3D_WARN("tracking metrics skipped: " << why);
    report->notes.push_back("Tracking metrics skipped: " + why + ".");
    return;
  }
  const MotOptions o = motOptions(a, classes);
  res->mot = evaluateMot(data.frames, o);
  report->mot = &res->mot;
  report->mot_options = o;
  report->id_stability_options.classes = classes;
  res->id_stability = evaluateIdStability(data.frames, report->id_stability_options);
  report->id_stability = &res->id_stability;
}

int runEval(const EvalArgs& a) {
  const auto t_start = std::chrono::steady_clock::now();
  std::set<std::string> metrics;
  for (const auto& m : splitList(a.metrics)) {
    if (m != "kitti" && m != "waymo" && m != "mot") throw std::invalid_argument("--metric: unknown '" + m + "'");
    metrics.insert(m);
  }
  std::vector<ObjectClass> classes;
  for (const auto& c : splitList(a.classes)) {
    const auto cls = classFromName(c);
    if (!cls) throw std::invalid_argument("--classes: unknown class '" + c + "' (Car, Pedestrian, Cyclist)");
    classes.push_back(*cls);
  }
  const std::string gt_format = a.gt_format == "auto" ? detectGtFormat(a.gt) : a.gt_format;
  const bool pred_bag = isBag(a.pred);
  const std::vector<std::string> sequences = parseSequenceList(a.sequences);
  const kitti::Calibration bag_calib = a.calib.empty() ? kitti::defaultCalibration() : kitti::readCalibration(a.calib);

  EvalReport report;
  EvalData data = loadData(a, gt_format, pred_bag, sequences);
  if (pred_bag) attachPredictionBag(a, gt_format == "bag", bag_calib, data, &report);

  if (a.min_points > 0) {
    std::optional<ProgressBar> bar;
    report.min_points = a.min_points;
    report.min_points_counts = ignoreLabelsWithFewReturns(data, a.min_points, a.threads, stageBar(bar, "returns"));
    report.label_returns = labelReturns(data);
  }
  report.gt_source = data.gt_description;
  report.pred_source = data.pred_description;
  report.num_frames = data.frames.size();
  for (const auto& f : data.frames) {
    report.num_gt += std::max(f.gt_labels.size(), f.gt_boxes.size());
    report.num_pred += std::max(f.pred_labels.size(), f.pred_boxes.size());
  }
  if (data.frames.empty()) throw std::runtime_error("no frames to evaluate");

  const auto t_eval = std::chrono::steady_clock::now();
  EvalResults results;
  if (metrics.count("kitti")) evalKitti(a, classes, data, &results, &report);
  if (metrics.count("waymo")) evalWaymo(a, classes, data, &results, &report);
  if (metrics.count("mot")) evalMot(a, classes, data, &results, &report);
  const auto t_end = std::chrono::steady_clock::now();
  report.seconds = std::chrono::duration<double>(t_end - t_eval).count();
  const auto pngs = writeReport(a.out, report);
  std::cout << headlineTable(report);
  std::cout << "frames " << report.num_frames << ", load " << std::chrono::duration<double>(t_eval - t_start).count()
            << " s, evaluation " << report.seconds << " s; report: " << (fs::path(a.out) / "report.md").string()
            << ", " << pngs.size() << " plots" << std::endl;
  return 0;
}

CommandRegistrar registrar(
    "eval", "KITTI AP (devkit rules), Waymo-style AP/APH and tracking metrics, with a report and plots",
    [](CLI::App& app) -> CommandRun {
      auto a = std::make_shared<EvalArgs>();
      app.footer(
          "Ground truth: a KITTI object folder (label_2, calib), a KITTI tracking folder (label_02, calib; "
          "--sequences) or a bag (--gt-topic). Predictions: KITTI object result files (FFFFFF.txt), tracking result "
          "files (SSSS.txt, with track ids), per-class comma-separated files (<Class>/SSSS.txt), or a bag of "
          "Object3DArray (--pred-topic). Bag boxes are converted to camera labels with --calib (default: KITTI-like) "
          "for the KITTI metrics, which cover the front camera view only. Output: REPORT_DIR/metrics.json, "
          "report.md, plots/*.png.");
      app.add_option("--gt", a->gt, "ground truth: KITTI folder or bag")->required()->check(CLI::ExistingPath);
      app.add_option("--pred", a->pred, "predictions: result folder or bag")->required()->check(CLI::ExistingPath);
      app.add_option("--out", a->out, "report folder (created)")->required();
      app.add_option("--metric", a->metrics, "comma-separated: kitti, waymo, mot")->capture_default_str();
      app.add_option("--sequences", a->sequences, "tracking sequences, e.g. 1-20 or 0001,0005 (default: all)");
      app.add_option("--classes", a->classes, "comma-separated classes")->capture_default_str();
      app.add_option("--gt-format", a->gt_format, "auto, object, tracking or bag")->capture_default_str();
      app.add_option("--gt-topic", a->gt_topic, "ground-truth topic in a bag")->capture_default_str();
      app.add_option("--pred-topic", a->pred_topic, "prediction topic in a bag")->capture_default_str();
      app.add_option("--calib", a->calib, "KITTI calibration file for bag boxes (default: KITTI-like)")
          ->check(CLI::ExistingFile);
      app.add_option("--bag-rate", a->bag_rate, "prediction bag with a tracking folder: frame rate, Hz")
          ->capture_default_str();
      app.add_option("--bag-start-time", a->bag_start_time, "prediction bag with a tracking folder: stamp of frame 0")
          ->capture_default_str();
      app.add_option("--stamp-tolerance", a->stamp_tolerance, "s, when matching bag messages to frames")
          ->capture_default_str();
      app.add_option("--mot-similarity", a->mot_similarity, "iou3d, bev or center")->capture_default_str();
      app.add_option("--mot-threshold", a->mot_threshold, "CLEAR MOT: minimum similarity of a match")
          ->capture_default_str();
      app.add_option("--mot-zero-distance", a->mot_zero_distance, "center similarity: metres at which it reaches 0")
          ->capture_default_str();
      app.add_option("--mot-max-range", a->mot_max_range,
                     "tracking metrics: leave out boxes further than this from the sensor, m (0 = all)")
          ->capture_default_str()
          ->check(CLI::NonNegativeNumber);
      app.add_option("--kitti-recall", a->kitti_recall,
                     "KITTI AP recall sampling: devkit (the official devkit's, right with >= 40 valid objects per "
                     "class and difficulty) or exact (precision at actual recall k/40; for small sets)")
          ->capture_default_str()
          ->check(CLI::IsMember({"devkit", "exact"}));
      app.add_option("--min-points", a->min_points,
                     "ignore, in every metric, ground-truth labels holding fewer than this many returns of their "
                     "frame's scan (points in the box grown by 0.1 m; as the Waymo Open Dataset): an unmatched one is "
                     "no miss, a prediction on it neither a true nor a false positive. Needs the scans beside the "
                     "labels (velodyne/); counts per label in REPORT_DIR/label_returns.csv. 0 = off")
          ->capture_default_str()
          ->check(CLI::NonNegativeNumber);
      app.add_option("--threads", a->threads, "worker threads")->capture_default_str()->check(CLI::PositiveNumber);
      return [a]() -> int { return runEval(*a); };
    });

}  // namespace
}  // namespace tools
}  // namespace ret3d
