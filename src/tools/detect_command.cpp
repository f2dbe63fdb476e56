// `ret3d detect`: runs the detection stages offline and writes KITTI result files.
//   ret3d detect --detections DIR --stages intra --intra-model models/kitti_pointrcnn/intra_rm.pt
//                --data ../shared/data/kitti_tracking --sequences 16-20 --out out/pred_intra
// The input boxes come from another detector's result files (--detections: KITTI object/tracking result files or
// the per-class CSV layout); `--stages` lists what runs on them, in order: "intra" (IntraRM) or "none" (the boxes
// pass through the same conversions, the fair baseline). The base detector stage ("base") runs on point clouds and
// joins here when the detector is built. "track" runs the tracker (CenterPoint's, real ego poses) and writes track ids;
// "inter" runs the tracker and InterRM on every tracked box (train/inter_trainer.h: TrackingRefiner).
#include <chrono>
#include <filesystem>
#include <iostream>
#include <map>
#include <sstream>

#include "ret3d/core/detections.h"
#include "ret3d/core/log.h"
#include "ret3d/core/progress.h"
#include "ret3d/eval/eval_data.h"
#include "ret3d/io/detections.h"
#include "ret3d/io/kitti.h"
#include "ret3d/relation/inter_rm.h"
#include "ret3d/relation/intra_rm.h"
#include "ret3d/train/inter_trainer.h"
#include "ret3d/tracking/tracker_options.h"
#include "tools/command.h"

namespace ret3d {
namespace tools {
namespace {

namespace fs = std::filesystem;

struct DetectArgs {
  std::string data, detections, out, stages = "intra", intra_model, sequences, inter_model, tracker_config;
  int threads = 2;
};

std::vector<std::string> splitStages(const std::string& s) {
  std::vector<std::string> out;
  std::stringstream ss(s);
  std::string item;
  while (std::getline(ss, item, ',')) {
    if (item.empty() || item == "none") continue;
    if (item != "intra" && item != "base" && item != "track" && item != "inter")
      throw std::runtime_error("--stages: unknown stage '" + item + "' (known: base, intra, track, inter, none)");
    out.push_back(item);
  }
  return out;
}

// The stages after the base detector, applied to one frame.
struct Stages {
  std::unique_ptr<relation::IntraRM> intra;
  std::unique_ptr<relation::InterRM> inter;
  std::unique_ptr<train::TrackingRefiner> tracking;  // stages track / inter: after the per-frame stages
  double seconds = 0;
  std::size_t frames = 0;
  Detections run(Detections d) {
    const auto t0 = std::chrono::steady_clock::now();
    if (intra) d = intra->refine(d);
    seconds += std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    ++frames;
    return d;
  }
};

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

int runDetect(const DetectArgs& a) {
  const std::vector<std::string> stages = splitStages(a.stages);
  if (a.detections.empty())
    throw std::runtime_error("--detections DIR is required: the base detector stage on point clouds is not "
                             "available in this build yet");
  Stages st;
  for (const std::string& s : stages) {
    if (s == "base")
      throw std::runtime_error("--stages base: the input boxes come from --detections; drop 'base' from --stages");
    if (s == "intra") {
      if (a.intra_model.empty()) throw std::runtime_error("--stages intra needs --intra-model FILE");
      relation::IntraRMOptions o;
      o.model_path = a.intra_model;
      o.threads = a.threads;
      st.intra = std::make_unique<relation::IntraRM>(o);
    }
    if (s == "inter") {
      if (a.inter_model.empty()) throw std::runtime_error("--stages inter needs --inter-model FILE");
      relation::InterRMOptions o;
      o.model_path = a.inter_model;
      o.threads = a.threads;
      st.inter = std::make_unique<relation::InterRM>(o);
    }
    if (s == "track" || s == "inter") {
      if (stages.back() != s) throw std::runtime_error("--stages: '" + s + "' must be the last stage");
      const TrackerOptions t = a.tracker_config.empty() ? TrackerOptions{} : loadTrackerOptions(a.tracker_config);
      st.tracking = std::make_unique<train::TrackingRefiner>(t, st.inter.get());
    }
  }
  if (a.data.empty() || a.out.empty()) throw std::runtime_error("--data and --out are required");
  fs::create_directories(a.out);
  const io::DetectionLayout layout = io::detectDetectionLayout(a.detections);
  std::size_t boxes = 0;
  if (layout == io::DetectionLayout::KittiObject && st.tracking)
    throw std::runtime_error("--stages track/inter need sequences: " + a.detections + " holds per-frame object results");
  if (layout == io::DetectionLayout::KittiObject) {
    kitti::ObjectDataset ds(a.data);
    const auto frames = ds.frames();
    ProgressBar bar("detect", frames.size());
    for (const std::string& fr : frames) {
      const kitti::Calibration calib = kitti::readCalibration(ds.calibPath(fr));
      const Detections d = st.run(toDetections(io::readFrameDetections(a.detections, fr), calib));
      boxes += d.size();
      kitti::writeObjectLabels(a.out + "/" + fr + ".txt", toLabels(d, calib, -1));
      bar.tick();
    }
  } else {
    kitti::TrackingDataset ds(a.data);
    std::vector<std::string> seqs =
        a.sequences.empty() ? ds.sequences() : eval::parseSequenceList(a.sequences);
    ProgressBar bar("detect", seqs.size());
    for (const std::string& seq : seqs) {
      const kitti::Calibration calib = kitti::readCalibration(ds.calibPath(seq));
      std::vector<kitti::Label> out;
      const auto dets = io::readSequenceDetections(a.detections, layout, seq);
      if (st.tracking) {
        // Every frame in order (frames without detections too: tracks coast), at 10 Hz, with the real ego poses.
        const auto poses = ds.lidarPoses(seq);
        if (poses.empty()) throw std::runtime_error("sequence " + seq + ": no ego poses (pose/ or oxts/) for tracking");
        if (!dets.empty() && dets.rbegin()->first >= static_cast<int>(poses.size()))
          throw std::runtime_error("sequence " + seq + ": detections in frame " +
                                   std::to_string(dets.rbegin()->first) + " beyond its " +
                                   std::to_string(poses.size()) + " poses");
        st.tracking->reset();
        for (int frame = 0; frame < static_cast<int>(poses.size()); ++frame) {
          const auto it = dets.find(frame);
          Detections d = st.run(it == dets.end() ? Detections{} : toDetections(it->second, calib));
          d.boxes = st.tracking->update(d.boxes, 0.1 * frame, poses[static_cast<std::size_t>(frame)]);
          d.features.clear(), d.feature_dim = 0;
          boxes += d.size();
          const auto l = toLabels(d, calib, frame);
          out.insert(out.end(), l.begin(), l.end());
        }
      } else {
        for (const auto& [frame, labels] : dets) {
          const Detections d = st.run(toDetections(labels, calib));
          boxes += d.size();
          const auto l = toLabels(d, calib, frame);
          out.insert(out.end(), l.begin(), l.end());
        }
      }
      kitti::writeTrackingLabels(a.out + "/" + seq + ".txt", out);
      bar.tick();
    }
  }
  std::cout << "detect: " << st.frames << " frames, " << boxes << " boxes written to " << a.out;
  if (st.intra && st.frames > 0)
    std::cout << "; IntraRM " << 1000.0 * st.seconds / static_cast<double>(st.frames) << " ms per frame";
  if (st.tracking && st.tracking->frames() > 0) {
    const double n = static_cast<double>(st.tracking->frames());
    std::cout << "; tracker " << 1000.0 * st.tracking->trackerSeconds() / n << " ms per frame";
    if (st.inter) std::cout << ", InterRM " << 1000.0 * st.tracking->interSeconds() / n << " ms per frame";
  }
  std::cout << std::endl;
  return 0;
}

CommandRegistrar reg("detect", "run detection stages offline (IntraRM on another detector's boxes) to KITTI results",
                     [](CLI::App& app) -> CommandRun {
  auto a = std::make_shared<DetectArgs>();
  app.add_option("--data", a->data, "KITTI tracking or object root (calibration)");
  app.add_option("--detections", a->detections,
                 "input boxes: KITTI object/tracking result files or per-class CSV folders");
  app.add_option("--stages", a->stages, "comma-separated stages to run: intra, track, inter, none")->capture_default_str();
  app.add_option("--intra-model", a->intra_model, "IntraRM model file (for the intra stage)");
  app.add_option("--inter-model", a->inter_model, "InterRM model file (for the inter stage)");
  app.add_option("--tracker-config", a->tracker_config, "tracker YAML for track/inter (default: config/tracker.yaml's "
                 "values, built in)");
  app.add_option("--sequences", a->sequences, "tracking sequences, e.g. 16-20 (default: all)");
  app.add_option("--out", a->out, "output folder for KITTI result files");
  app.add_option("--threads", a->threads, "CPU threads for libtorch")->capture_default_str();
  return [a]() { return runDetect(*a); };
});

}  // namespace
}  // namespace tools
}  // namespace ret3d
