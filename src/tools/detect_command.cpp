// `ret3d detect`: runs the pipeline offline over a KITTI-layout folder and writes KITTI result files: one per frame
// for the object layout, one per sequence (tracking result format, with track ids after `track`/`inter`) for the
// tracking layout.
//   ret3d detect --data data/sim_test_urban --models models/lwd3d --out out/pred --stages base
//   ret3d detect --detections ../shared/data/kitti_tracking/detections/pointrcnn --stages intra
//                --intra-model models/kitti_pointrcnn/intra_rm.pt --data ../shared/data/kitti_tracking
//                --sequences 16-20 --out out/pred_intra
// With the `base` stage the boxes come from the LWD-3D detector on the folder's scans (the previous sweep moved by
// the ego motion of --poses, pose/ or oxts/, or else estimated from the scans by scan matching); without it they come
// from another detector's result files (--detections: KITTI object/tracking result files or the per-class CSV layout).
// `--stages` lists what runs, in order: base, intra (IntraRM), track (the CenterPoint-style tracker, in the fixed
// frame of the ego poses), inter (tracker + InterRM), or none (the boxes pass through the same conversions: the fair
// baseline).
#include <filesystem>
#include <fstream>
#include <iostream>
#include <map>
#include <sstream>

#include "ret3d/core/detections.h"
#include "ret3d/core/json_writer.h"
#include "ret3d/core/log.h"
#include "ret3d/core/progress.h"
#include "ret3d/core/stats.h"
#include "ret3d/eval/eval_data.h"
#include "ret3d/eval/velocity_error.h"
#include "ret3d/io/detections.h"
#include "ret3d/io/ego_motion.h"
#include "ret3d/io/kitti.h"
#include "ret3d/io/sweeps.h"
#include "ret3d/io/track_velocity.h"
#include "tools/command.h"
#include "tools/pipeline_options.h"

namespace ret3d {
namespace tools {
namespace {

namespace fs = std::filesystem;

struct DetectArgs {
  pipeline::PipelineConfig pipeline;
  std::string data, detections, out, stages = "base", sequences, velocity_report, poses;
};

// The ego poses of `seq` (--poses, pose/ or oxts/, else estimated from its scans); throws when the tracker needs
// them and there are none, or when they end before the frames do.
std::vector<Eigen::Isometry3d> egoPoses(const DetectArgs& a, const kitti::TrackingDataset& ds, const std::string& seq,
                                        bool tracks, int last_frame) {
  const auto poses = io::sequenceLidarPoses(ds, seq, {a.poses, /*scan_matching=*/true});
  if (poses.empty() && tracks)
    throw std::runtime_error("sequence " + seq + ": no ego poses for tracking (pose/ or oxts/, no scans to estimate "
                             "them from); give --poses FILE");
  if (!poses.empty() && last_frame >= static_cast<int>(poses.size()))
    throw std::runtime_error("sequence " + seq + ": frame " + std::to_string(last_frame) + " beyond its " +
                             std::to_string(poses.size()) + " ego poses" +
                             (a.poses.empty() ? "" : " (" + a.poses + ")"));
  return poses;
}

// Ground truth with velocities (from the track ids and the ego poses) of one labelled sequence, per frame.
std::vector<eval::VelocityFrame> velocityGroundTruth(const kitti::TrackingDataset& ds, const std::string& seq,
                                                     const kitti::Calibration& calib,
                                                     const std::vector<Eigen::Isometry3d>& poses) {
  std::vector<std::vector<Box>> boxes;
  for (const kitti::Label& l : kitti::readTrackingLabels(ds.labelPath(seq))) {
    if (l.frame < 0 || !classFromName(l.type)) continue;
    if (static_cast<int>(boxes.size()) <= l.frame) boxes.resize(static_cast<std::size_t>(l.frame) + 1);
    boxes[static_cast<std::size_t>(l.frame)].push_back(kitti::labelToBox(l, calib));
  }
  const auto valid = setTrackVelocities(&boxes, poses, 0.1);
  std::vector<eval::VelocityFrame> out(boxes.size());
  for (std::size_t f = 0; f < boxes.size(); ++f) out[f].gt = boxes[f], out[f].gt_valid = valid[f];
  return out;
}

void reportVelocity(const std::vector<eval::VelocityFrame>& frames, const std::string& path) {
  const auto stats = eval::velocityErrors(frames);
  JsonWriter json;
  for (const auto& [cls, s] : stats) {
    std::cout << "velocity error " << className(cls) << ": moving objects (> 0.5 m/s) median " << s.moving_median
              << " m/s, p90 " << s.moving_p90 << " m/s over " << s.moving_matched << " matched of " << s.moving_gt
              << "; static median " << s.static_median << " m/s over " << s.static_matched << "\n";
    json.beginObject(className(cls))
        .field("moving_median", s.moving_median)
        .field("moving_p90", s.moving_p90)
        .field("moving_matched", s.moving_matched)
        .field("moving_gt", s.moving_gt)
        .field("static_median", s.static_median)
        .field("static_matched", s.static_matched)
        .endObject();
  }
  if (!path.empty()) {
    json.save(path);
    std::cout << "velocity errors written to " << path << "\n";
  }
}

Detections toDetections(const std::vector<kitti::Label>& labels, const kitti::Calibration& calib) {
  Detections d;
  for (const kitti::Label& l : labels)
    if (classFromName(l.type)) d.boxes.push_back(kitti::labelToBox(l, calib));
  return d;
}

std::vector<kitti::Label> toLabels(const Detections& d, const kitti::Calibration& calib, int frame) {
  std::vector<kitti::Label> out;
  for (const Box& b : d.boxes) {
    kitti::Label l = kitti::boxToLabel(b, calib);
    l.frame = frame;  // track id: Box::track_id - 1 (boxToLabel), -1 when untracked
    out.push_back(l);
  }
  return out;
}

// True when ROOT (or ROOT/training) holds velodyne/FFFFFF.bin files directly: the object layout.
bool isObjectLayout(const std::string& root) {
  for (const fs::path& dir : {fs::path(root) / "training" / "velodyne", fs::path(root) / "velodyne"}) {
    if (!fs::is_directory(dir)) continue;
    for (const auto& e : fs::directory_iterator(dir))
      if (e.is_regular_file() && e.path().extension() == ".bin") return true;
    return false;
  }
  return false;
}

// Every frame of a KITTI object folder: `detect` gives its boxes, written as a KITTI object result file.
template <class DetectFrame>
std::size_t detectObjectFrames(const DetectArgs& a, DetectFrame detect) {
  kitti::ObjectDataset ds(a.data);
  const auto frames = ds.frames();
  ProgressBar bar("detect", frames.size());
  std::size_t boxes = 0;
  for (const std::string& fr : frames) {
    const kitti::Calibration calib = ds.calibration(fr);
    const Detections d = detect(ds, fr, calib);
    boxes += d.size();
    kitti::writeObjectLabels(a.out + "/" + fr + ".txt", toLabels(d, calib, -1));
    bar.tick();
  }
  return boxes;
}

// --sequences, or every sequence; --poses holds one sequence's poses.
std::vector<std::string> sequencesToRun(const DetectArgs& a, const kitti::TrackingDataset& ds) {
  const std::vector<std::string> seqs = a.sequences.empty() ? ds.sequences() : eval::parseSequenceList(a.sequences);
  if (!a.poses.empty() && seqs.size() != 1)
    throw std::runtime_error("--poses " + a.poses + " holds one sequence's poses; " + std::to_string(seqs.size()) +
                             " sequences would run (give one with --sequences)");
  return seqs;
}

// The base detector on a KITTI-layout folder's scans.
std::size_t detectFromScans(const DetectArgs& a, pipeline::OfflinePipeline* p) {
  std::size_t boxes = 0;
  if (isObjectLayout(a.data)) {
    if (p->tracks()) throw std::runtime_error("--stages track/inter need sequences: " + a.data + " has the object layout");
    return detectObjectFrames(a, [&](const kitti::ObjectDataset& ds, const std::string& fr, const kitti::Calibration&) {
      const PointCloud cloud = kitti::readVelodyne(ds.velodynePath(fr));
      const Eigen::Isometry3d I = Eigen::Isometry3d::Identity();
      return p->run(&cloud, nullptr, I, {}, 0.0, I);
    });
  }
  kitti::TrackingDataset ds(a.data);
  const std::vector<std::string> seqs = sequencesToRun(a, ds);
  std::size_t total_frames = 0;
  for (const std::string& seq : seqs) total_frames += ds.frames(seq).size();
  std::vector<eval::VelocityFrame> velocity;  // labelled sequences: predictions beside the ground truth
  ProgressBar bar("detect", total_frames);
  for (const std::string& seq : seqs) {
    const kitti::Calibration calib = ds.calibration(seq);
    const std::vector<int> frames = ds.frames(seq);
    const auto poses = egoPoses(a, ds, seq, p->tracks(), frames.empty() ? -1 : frames.back());
    p->reset();
    std::vector<eval::VelocityFrame> vel;
    if (ds.hasLabels(seq)) vel = velocityGroundTruth(ds, seq, calib, poses);
    std::vector<kitti::Label> out;
    io::forEachSweep(ds, seq, poses, [&](const io::Sweep& s) {
      const Detections d = p->run(s.cloud, s.previous, s.prev_to_current, {}, 0.1 * s.frame, s.pose);
      boxes += d.size();
      if (s.frame < static_cast<int>(vel.size())) vel[static_cast<std::size_t>(s.frame)].pred = d.boxes;
      const auto l = toLabels(d, calib, s.frame);
      out.insert(out.end(), l.begin(), l.end());
      bar.tick();
    });
    kitti::writeTrackingLabels(a.out + "/" + seq + ".txt", out);
    velocity.insert(velocity.end(), vel.begin(), vel.end());
  }
  if (!velocity.empty()) reportVelocity(velocity, a.velocity_report);
  return boxes;
}

// The later stages on another detector's result files.
std::size_t detectFromResults(const DetectArgs& a, pipeline::OfflinePipeline* p) {
  const io::DetectionLayout layout = io::detectDetectionLayout(a.detections);
  const Eigen::Isometry3d I = Eigen::Isometry3d::Identity();
  std::size_t boxes = 0;
  if (layout == io::DetectionLayout::KittiObject) {
    if (p->tracks())
      throw std::runtime_error("--stages track/inter need sequences: " + a.detections + " holds per-frame object results");
    return detectObjectFrames(a, [&](const kitti::ObjectDataset&, const std::string& fr, const kitti::Calibration& calib) {
      return p->run(nullptr, nullptr, I, toDetections(io::readFrameDetections(a.detections, fr), calib), 0, I);
    });
  }
  kitti::TrackingDataset ds(a.data);
  const std::vector<std::string> seqs = sequencesToRun(a, ds);
  ProgressBar bar("detect", seqs.size());
  for (const std::string& seq : seqs) {
    const kitti::Calibration calib = kitti::readCalibration(ds.calibPath(seq));
    std::vector<kitti::Label> out;
    const auto dets = io::readSequenceDetections(a.detections, layout, seq);
    if (p->tracks()) {
      // Every frame in order (frames without detections too: tracks coast), at 10 Hz, with the ego poses.
      const auto poses = egoPoses(a, ds, seq, true, dets.empty() ? -1 : dets.rbegin()->first);
      p->reset();
      for (int frame = 0; frame < static_cast<int>(poses.size()); ++frame) {
        const auto it = dets.find(frame);
        const Detections d = p->run(nullptr, nullptr, I, it == dets.end() ? Detections{} : toDetections(it->second, calib),
                                    0.1 * frame, poses[static_cast<std::size_t>(frame)]);
        boxes += d.size();
        const auto l = toLabels(d, calib, frame);
        out.insert(out.end(), l.begin(), l.end());
      }
    } else {
      for (const auto& [frame, labels] : dets) {
        const Detections d = p->run(nullptr, nullptr, I, toDetections(labels, calib), 0, I);
        boxes += d.size();
        const auto l = toLabels(d, calib, frame);
        out.insert(out.end(), l.begin(), l.end());
      }
    }
    kitti::writeTrackingLabels(a.out + "/" + seq + ".txt", out);
    bar.tick();
  }
  return boxes;
}

int runDetect(DetectArgs a) {
  a.pipeline.stages = pipeline::parseStages(a.stages);
  const bool base = !a.pipeline.stages.empty() && a.pipeline.stages.front() == "base";
  if (a.data.empty() || a.out.empty()) throw std::runtime_error("--data and --out are required");
  if (base && !a.detections.empty())
    throw std::runtime_error("--detections and the base stage exclude each other: the base stage makes the boxes");
  if (!base && a.detections.empty())
    throw std::runtime_error("without the base stage the boxes come from --detections DIR (another detector's results)");
  pipeline::OfflinePipeline p(withPackageDir(a.pipeline));
  std::cout << "detect: " << p.describe() << std::endl;
  fs::create_directories(a.out);
  const std::size_t boxes = base ? detectFromScans(a, &p) : detectFromResults(a, &p);
  const auto& t = p.times().all();
  const std::size_t frames = t.count("total") ? t.at("total").size() : 0;
  std::cout << "detect: " << frames << " frames, " << boxes << " boxes written to " << a.out;
  for (const char* stage : {"bev", "network", "decode", "nms", "refine", "intra", "track", "inter", "total"})
    if (t.count(stage)) std::cout << "; " << stage << " " << median(t.at(stage)) << " ms";
  std::cout << " (medians per frame; `ret3d bench` for timings)" << std::endl;
  return 0;
}

CommandRegistrar reg("detect", "run the pipeline offline (base detector, IntraRM, tracker, InterRM) to KITTI results",
                     [](CLI::App& app) -> CommandRun {
  auto a = std::make_shared<DetectArgs>();
  pipeline::PipelineConfig& p = a->pipeline;
  app.add_option("--data", a->data, "KITTI tracking or object root (scans for the base stage, calibration, poses), or a "
                 "plain folder of consecutive FFFFFF.bin scans (one sequence, 0000)")
      ->required();
  app.add_option("--detections", a->detections,
                 "without the base stage: input boxes (KITTI object/tracking result files or per-class CSV folders)");
  app.add_option("--stages", a->stages, "comma-separated stages in order: base, intra, track, inter; none")
      ->capture_default_str();
  app.add_option("--models", p.models, "folder with detector.pt, intra_rm.pt, inter_rm.pt (e.g. models/lwd3d)");
  app.add_option("--detector-model", p.detector_model, "detector model file (overrides --models)");
  app.add_option("--detector-config", p.detector_config,
                 "detector YAML for inference options (default: the config stored in the model file)");
  addScoreThresholdOption(app, &p.score_threshold);
  addGridExtentOption(app, &p.grid_extent);
  app.add_option("--intra-model", p.intra_model, "IntraRM model file (overrides --models)");
  app.add_option("--inter-model", p.inter_model, "InterRM model file (overrides --models)");
  app.add_option("--tracker-config", p.tracker_config, "tracker YAML for track/inter (default: with the base stage "
                 "config/tracker_lwd3d_pipeline.yaml, as the nodelets; with --detections config/tracker.yaml's "
                 "values, built in)");
  app.add_option("--sequences", a->sequences, "tracking sequences, e.g. 16-20 (default: all)");
  app.add_option("--poses", a->poses, "ego poses of the one sequence run, in pose/SSSS.txt's format (camera poses, "
                 "KITTI odometry convention; e.g. what `ret3d autolabel` writes). Default: pose/ or oxts/, else the "
                 "ego motion is estimated from the scans (scan matching, as `ret3d autolabel`)");
  app.add_option("--out", a->out, "output folder for KITTI result files")->required();
  app.add_option("--threads", p.threads, "CPU threads for libtorch")->capture_default_str();
  app.add_option("--velocity-report", a->velocity_report,
                 "labelled tracking data with the base stage: write the velocity errors (JSON) here");
  return [a]() { return runDetect(*a); };
});

}  // namespace
}  // namespace tools
}  // namespace ret3d
