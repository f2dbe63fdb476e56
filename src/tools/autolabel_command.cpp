// `ret3d autolabel`: offline pseudo-labels for self-training. Runs the pipeline of `ret3d detect` (detector, IntraRM,
// tracker, InterRM) over every sequence of unlabelled scans, then refines each track with its past and future boxes
// (tracking/track_smoothing.h: one size per track, smoothed centres and headings, gaps filled, weak tracks dropped)
// and writes a KITTI tracking dataset that `ret3d train detector --data OUT` trains on:
//   ret3d autolabel --data ../shared/data/unlabeled_scans --out data/pseudo --models models/lwd3d
//   OUT/training/velodyne/SSSS/FFFFFF.bin  symlinks to the input scans (copies with --copy-scans)
//   OUT/training/label_02/SSSS.txt         pseudo-labels, with the track's mean score in the score field
//   OUT/training/calib/SSSS.txt            the input's calibration (kitti::defaultCalibration() for a scan folder)
//   OUT/training/pose/SSSS.txt             the input's ego poses, or those estimated from the scans (ICP)
// --data is a KITTI tracking layout or a plain folder of consecutive scans (one sequence, 0000).
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <iomanip>
#include <iostream>
#include <map>

#include "ret3d/core/log.h"
#include "ret3d/core/progress.h"
#include "ret3d/core/transform.h"
#include "ret3d/eval/eval_data.h"
#include "ret3d/io/ego_motion.h"
#include "ret3d/io/kitti.h"
#include "ret3d/io/sweeps.h"
#include "ret3d/sim/sequence_writer.h"
#include "ret3d/tracking/track_smoothing.h"
#include "tools/command.h"
#include "tools/pipeline_options.h"

namespace ret3d {
namespace tools {
namespace {

namespace fs = std::filesystem;
using Clock = std::chrono::steady_clock;

constexpr double kFramePeriod = 0.1;  // s: KITTI's 10 Hz, as `ret3d detect` stamps frames

struct AutolabelArgs {
  pipeline::PipelineConfig pipeline;
  TrackSmoothingOptions smoothing;
  std::string data, out, stages = "base,intra,track,inter", sequences;
  bool copy_scans = false, no_scan_matching = false;
};

double secondsSince(Clock::time_point t0) { return std::chrono::duration<double>(Clock::now() - t0).count(); }

void linkOrCopyScan(const std::string& from, const std::string& to, bool copy) {
  std::error_code ec;
  fs::remove(to, ec);
  if (copy)
    fs::copy_file(from, to, ec);
  else
    fs::create_symlink(fs::absolute(from), to, ec);
  if (ec)
    throw std::runtime_error(std::string("cannot ") + (copy ? "copy " : "link ") + from + " to " + to + ": " +
                             ec.message());
}

// Boxes per class, summed over frames.
using ClassCounts = std::map<ObjectClass, std::size_t>;
void countBoxes(const std::vector<Box>& boxes, ClassCounts* c) {
  for (const Box& b : boxes) ++(*c)[b.label];
}

struct Totals {
  std::size_t frames = 0;
  ClassCounts raw, smoothed;
  TrackSmoothingStats stats;
  double matching_s = 0, pipeline_s = 0, smoothing_s = 0;
};

// The sequence's LiDAR poses: given (pose/, OXTS), else estimated by scan matching, else (--no-scan-matching)
// identities; *have_poses says whether they are real.
std::vector<Eigen::Isometry3d> sequencePoses(const AutolabelArgs& a, const kitti::TrackingDataset& ds,
                                             const std::string& seq, const std::vector<int>& frames, Totals* totals,
                                             bool* have_poses) {
  std::vector<Eigen::Isometry3d> poses = ds.lidarPoses(seq);
  if (poses.empty()) {
    if (a.no_scan_matching) {
      RET3D_WARN("sequence " << seq << ": no ego poses; tracks are smoothed in the sensor frame");
    } else {
      const auto t0 = Clock::now();
      poses = io::estimateLidarPoses(ds, seq);
      totals->matching_s += secondsSince(t0);
    }
  }
  *have_poses = !poses.empty();
  if (!*have_poses) poses.assign(static_cast<std::size_t>(frames.back()) + 1, Eigen::Isometry3d::Identity());
  if (static_cast<int>(poses.size()) <= frames.back())
    throw std::runtime_error("sequence " + seq + ": " + std::to_string(poses.size()) +
                             " ego poses for scans up to frame " + std::to_string(frames.back()));
  return poses;
}

// The pipeline, online as in `ret3d detect`; its tracked boxes moved into the fixed frame of the first scan, per
// frame index. Links (or copies) each scan into OUT.
std::vector<std::vector<Box>> trackedBoxesInWorld(const AutolabelArgs& a, const kitti::TrackingDataset& ds,
                                                  const std::string& seq, const std::vector<int>& frames,
                                                  const std::vector<Eigen::Isometry3d>& poses,
                                                  pipeline::OfflinePipeline* p, Totals* totals) {
  const fs::path out = fs::path(a.out) / "training";
  fs::create_directories(out / "velodyne" / seq);
  std::vector<std::vector<Box>> world(static_cast<std::size_t>(frames.back()) + 1);
  const auto t0 = Clock::now();
  p->reset();
  ProgressBar bar("autolabel " + seq, frames.size());
  io::forEachSweep(ds, seq, poses, [&](const io::Sweep& s) {
    const Detections d = p->run(s.cloud, s.previous, s.prev_to_current, {}, kFramePeriod * s.frame, s.pose);
    for (const Box& b : d.boxes) world[static_cast<std::size_t>(s.frame)].push_back(transformBox(b, s.pose));
    countBoxes(d.boxes, &totals->raw);
    char name[32];
    std::snprintf(name, sizeof(name), "%06d.bin", s.frame);
    linkOrCopyScan(ds.velodynePath(seq, s.frame), (out / "velodyne" / seq / name).string(), a.copy_scans);
    bar.tick();
  });
  totals->pipeline_s += secondsSince(t0);
  totals->frames += frames.size();
  return world;
}

// The smoothed boxes back in each scan's sensor frame as KITTI labels. A frame index without a scan (a gap in the
// files) gets no labels: there is nothing to train on. Every box, also outside the camera's view: the detector trains
// on the whole scan.
std::vector<kitti::Label> sensorFrameLabels(const std::vector<std::vector<Box>>& smoothed, const std::vector<int>& frames,
                                            const std::vector<Eigen::Isometry3d>& poses,
                                            const kitti::Calibration& calib, Totals* totals) {
  std::vector<kitti::Label> labels;
  for (const int f : frames) {
    const Eigen::Isometry3d to_sensor = poses[static_cast<std::size_t>(f)].inverse();
    std::vector<Box> boxes;
    for (const Box& b : smoothed[static_cast<std::size_t>(f)]) boxes.push_back(transformBox(b, to_sensor));
    countBoxes(boxes, &totals->smoothed);
    for (const Box& b : boxes) {
      kitti::Label l = kitti::boxToLabel(b, calib);
      l.frame = f;
      labels.push_back(l);
    }
  }
  return labels;
}

// OUT's pose file: the dataset's copied, else the poses used (camera poses in KITTI's odometry convention, the inverse
// of kitti::cameraPosesToLidar) when they are real.
void writeSequencePoses(const kitti::TrackingDataset& ds, const std::string& seq, const fs::path& out,
                        const kitti::Calibration& calib, const std::vector<Eigen::Isometry3d>& poses, bool have_poses) {
  if (fs::exists(ds.posePath(seq))) {
    fs::copy_file(ds.posePath(seq), out / "pose" / (seq + ".txt"), fs::copy_options::overwrite_existing);
  } else if (have_poses) {
    const Eigen::Isometry3d Tr = sim::lidarToCamera(calib), Tr_inv = Tr.inverse();
    std::vector<Eigen::Isometry3d> cam;
    for (const auto& P : poses) cam.push_back(Tr * P * Tr_inv);
    kitti::writePoses((out / "pose" / (seq + ".txt")).string(), cam);
  }
}

void labelSequence(const AutolabelArgs& a, const kitti::TrackingDataset& ds, const std::string& seq,
                   pipeline::OfflinePipeline* p, Totals* totals) {
  const fs::path out = fs::path(a.out) / "training";
  const std::vector<int> frames = ds.frames(seq);
  if (frames.empty()) {
    RET3D_WARN("sequence " << seq << ": no scans; skipped");
    return;
  }
  if (ds.isScanFolder())
    RET3D_WARN(ds.dir() << ": a folder of scans without calibration; the KITTI default is written");
  const kitti::Calibration calib = ds.calibration(seq);
  bool have_poses = false;
  const std::vector<Eigen::Isometry3d> poses = sequencePoses(a, ds, seq, frames, totals, &have_poses);
  const std::vector<std::vector<Box>> world = trackedBoxesInWorld(a, ds, seq, frames, poses, p, totals);

  const auto t1 = Clock::now();
  TrackSmoothingStats stats;
  const auto smoothed = smoothTracks(world, a.smoothing, &stats);
  totals->smoothing_s += secondsSince(t1);
  kitti::writeTrackingLabels((out / "label_02" / (seq + ".txt")).string(),
                             sensorFrameLabels(smoothed, frames, poses, calib, totals));
  kitti::writeCalibration((out / "calib" / (seq + ".txt")).string(), calib);
  writeSequencePoses(ds, seq, out, calib, poses, have_poses);
  std::cout << "sequence " << seq << ": " << stats.tracks_in << " tracks, " << stats.tracks_kept << " kept, "
            << stats.dropped_short << " dropped as shorter than " << a.smoothing.min_track_length << " frames, "
            << stats.dropped_score << " with a mean score below " << a.smoothing.min_track_score << "; "
            << stats.boxes_in << " tracked boxes -> " << stats.boxes_out << " labels (" << stats.boxes_filled
            << " in filled gaps)" << std::endl;
  totals->stats.tracks_in += stats.tracks_in, totals->stats.tracks_kept += stats.tracks_kept;
  totals->stats.dropped_short += stats.dropped_short, totals->stats.dropped_score += stats.dropped_score;
  totals->stats.boxes_in += stats.boxes_in, totals->stats.boxes_out += stats.boxes_out;
  totals->stats.boxes_filled += stats.boxes_filled;
}

int runAutolabel(AutolabelArgs a) {
  a.pipeline.stages = pipeline::parseStages(a.stages);
  const auto& st = a.pipeline.stages;
  if (st.empty() || st.front() != "base")
    throw std::runtime_error("--stages must start with base: autolabel detects on the scans of --data");
  if (std::find(st.begin(), st.end(), "track") == st.end() && std::find(st.begin(), st.end(), "inter") == st.end())
    throw std::runtime_error("--stages needs track or inter: the labels are smoothed per track");
  std::error_code ec;
  if (fs::equivalent(a.data, a.out, ec)) throw std::runtime_error("--out must differ from --data (" + a.out + ")");
  const auto t0 = Clock::now();
  kitti::TrackingDataset ds(a.data);
  const std::vector<std::string> seqs = a.sequences.empty() ? ds.sequences() : eval::parseSequenceList(a.sequences);
  std::size_t with_scans = 0;
  for (const std::string& seq : seqs) with_scans += ds.frames(seq).empty() ? 0 : 1;
  if (with_scans == 0)
    throw std::runtime_error(a.data + ": no sequences with scans (a KITTI tracking layout, training/velodyne/SSSS/"
                             "FFFFFF.bin, or a folder of FFFFFF.bin scans expected)");
  for (const char* sub : {"velodyne", "label_02", "calib", "pose"})
    fs::create_directories(fs::path(a.out) / "training" / sub);
  pipeline::OfflinePipeline p(withPackageDir(a.pipeline));
  std::cout << "autolabel: " << p.describe() << std::endl;
  Totals t;
  for (const std::string& seq : seqs) labelSequence(a, ds, seq, &p, &t);

  const double n = std::max<std::size_t>(1, t.frames);
  std::cout << "autolabel: " << t.frames << " frames; tracks " << t.stats.tracks_in << " -> " << t.stats.tracks_kept
            << " kept (" << t.stats.dropped_short << " short, " << t.stats.dropped_score << " weak); boxes per frame "
            << "(pipeline -> labels):";
  for (const ObjectClass c : kDetectedClasses)
    std::cout << " " << className(c) << " " << std::fixed << std::setprecision(2) << t.raw[c] / n << " -> "
              << t.smoothed[c] / n;
  std::cout << std::defaultfloat << std::setprecision(6) << "\nautolabel: " << std::fixed << std::setprecision(1)
            << secondsSince(t0) << " s (ego motion " << t.matching_s << " s, pipeline " << t.pipeline_s
            << " s, smoothing " << std::setprecision(3) << t.smoothing_s << " s); dataset written to "
            << (fs::path(a.out) / "training").string() << std::defaultfloat << std::setprecision(6) << std::endl;
  return 0;
}

CommandRegistrar reg("autolabel", "pseudo-labels for unlabelled sequences: pipeline + offline track smoothing, "
                     "written as a KITTI tracking dataset",
                     [](CLI::App& app) -> CommandRun {
  auto a = std::make_shared<AutolabelArgs>();
  pipeline::PipelineConfig& p = a->pipeline;
  p.models = "models/lwd3d";
  TrackSmoothingOptions& s = a->smoothing;
  app.add_option("--data", a->data, "unlabelled scans: a KITTI tracking root (training/velodyne/SSSS/FFFFFF.bin, "
                 "optional calib/, pose/ or oxts/) or a plain folder of consecutive FFFFFF.bin scans")->required();
  app.add_option("--out", a->out, "output dataset root (KITTI tracking layout under OUT/training)")->required();
  app.add_option("--models", p.models, "folder with detector.pt, intra_rm.pt, inter_rm.pt")->capture_default_str();
  app.add_option("--detector-model", p.detector_model, "detector model file (overrides --models)");
  app.add_option("--detector-config", p.detector_config,
                 "detector YAML for inference options (default: the config stored in the model file)");
  app.add_option("--intra-model", p.intra_model, "IntraRM model file (overrides --models)");
  app.add_option("--inter-model", p.inter_model, "InterRM model file (overrides --models)");
  app.add_option("--tracker-config", p.tracker_config,
                 "tracker YAML (default: config/tracker_lwd3d_pipeline.yaml, as the nodelets)");
  app.add_option("--stages", a->stages, "comma-separated pipeline stages: base first, track or inter needed")
      ->capture_default_str();
  addScoreThresholdOption(app, &p.score_threshold);
  addGridExtentOption(app, &p.grid_extent);
  app.add_option("--sequences", a->sequences, "tracking sequences, e.g. 0-3 (default: all)");
  app.add_option("--min-track-length", s.min_track_length, "drop tracks seen in fewer frames")->capture_default_str();
  app.add_option("--min-track-score", s.min_track_score, "drop tracks with a lower mean score")->capture_default_str();
  app.add_option("--smoothing-window", s.half_window, "half width k (frames) of the centre fit and heading mean")
      ->capture_default_str();
  app.add_option("--max-gap", s.max_gap, "fill missed frames inside a track up to this many in a row")
      ->capture_default_str();
  app.add_flag("--copy-scans", a->copy_scans, "copy the scans into OUT instead of symlinking them");
  app.add_flag("--no-scan-matching", a->no_scan_matching,
               "without ego poses, smooth in the sensor frame instead of estimating the motion from the scans");
  app.add_option("--threads", p.threads, "CPU threads for libtorch")->capture_default_str();
  return [a]() { return runAutolabel(*a); };
});

}  // namespace
}  // namespace tools
}  // namespace ret3d
