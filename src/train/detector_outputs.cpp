#include "ret3d/train/detector_outputs.h"

#include <filesystem>

#include "ret3d/core/log.h"
#include "ret3d/core/progress.h"
#include "ret3d/detector/detector.h"
#include "ret3d/io/kitti.h"
#include "ret3d/io/sweeps.h"

namespace ret3d {
namespace train {

io::SequenceDetections detectSequences(const std::string& data_dir, const std::vector<std::string>& sequences,
                                       const DetectorOptions& detector, const std::string& cache_path, bool progress) {
  namespace fs = std::filesystem;
  kitti::TrackingDataset ds(data_dir);
  const std::vector<std::string> seqs = sequences.empty() ? ds.sequences() : sequences;
  // What the outputs depend on: the model file (path, size, time), the inference options that change the boxes,
  // and the data.
  const std::string model = detector.inference.model_path;
  std::string key = "model " + fs::absolute(model).string();
  if (fs::exists(model))
    key += " " + std::to_string(fs::file_size(model)) + " " +
           std::to_string(fs::last_write_time(model).time_since_epoch().count());
  key += " score " + detector.inference.describeScoreThresholds() + " candidates " +
         std::to_string(detector.inference.candidate_threshold) + " nms " +
         std::to_string(detector.inference.nms_iou) + " max " + std::to_string(detector.inference.max_detections) +
         " data " + fs::absolute(ds.dir()).string() + " sequences";
  for (const std::string& s : seqs) key += " " + s;
  io::SequenceDetections out;
  if (!cache_path.empty() && io::readDetectionCache(cache_path, key, &out)) {
    RET3D_INFO("detector outputs: " << out.size() << " sequences from the cache " << cache_path);
    return out;
  }
  Detector det(detector);
  std::size_t frames = 0;
  for (const std::string& s : seqs) frames += ds.frames(s).size();
  ProgressBar bar("detect " + fs::path(model).filename().string(), progress ? frames : 0);
  for (const std::string& seq : seqs) {
    io::forEachSweep(ds, seq, [&](const io::Sweep& s) {
      out[seq][s.frame] = det.detect(*s.cloud, s.previous, s.prev_to_current);
      if (progress) bar.tick();
    });
  }
  if (!cache_path.empty()) {
    if (fs::path(cache_path).has_parent_path()) fs::create_directories(fs::path(cache_path).parent_path());
    io::writeDetectionCache(cache_path, key, out);
    RET3D_INFO("detector outputs cached in " << cache_path);
  }
  return out;
}

}  // namespace train
}  // namespace ret3d
