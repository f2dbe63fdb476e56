// Fuzz target: the KITTI and detection-file readers (src/io). The first byte picks the reader, the rest is the file:
//   0 object labels (label_2)   1 tracking labels (label_02)   2 calibration   3 poses   4 OXTS
//   5 per-class CSV detections  6 velodyne .bin scan           7 detection cache (key "fuzz")
// A reader must return or throw std::runtime_error (kitti::ParseError is one) naming the file; what it returns is
// used the way the package uses it (labels to boxes and back to text, poses to LiDAR poses, ...), which must not fail.
#include <cmath>
#include <stdexcept>

#include "fuzz_util.h"
#include "ret3d/io/detection_cache.h"
#include "ret3d/io/detections.h"
#include "ret3d/io/kitti.h"

namespace {

using namespace ret3d;

void useLabels(const std::vector<kitti::Label>& labels, bool tracking) {
  const kitti::Calibration calib = kitti::defaultCalibration();
  for (const auto& l : labels) {
    const Box b = kitti::labelToBox(l, calib);
    kitti::boxToLabel(b, calib);
    if (tracking && l.frame >= 0) kitti::formatTrackingLabel(l);
    kitti::formatObjectLabel(l);
  }
}

void read(std::uint8_t which, const std::string& path) {
  switch (which % 8) {
    case 0:
      useLabels(kitti::readObjectLabels(path), false);
      break;
    case 1:
      useLabels(kitti::readTrackingLabels(path), true);
      break;
    case 2: {
      const kitti::Calibration c = kitti::readCalibration(path);
      c.veloToRect(Eigen::Vector3d(10, 1, -1));
      c.rectToVelo(Eigen::Vector3d(1, 1, 10));
      c.projectRect(Eigen::Vector3d(1, 1, 10));
      kitti::imageRegionWedge(c, 0, kitti::kImageSize.x() - 1, 0, kitti::kImageSize.y() - 1);
      break;
    }
    case 3:
      kitti::cameraPosesToLidar(kitti::readPoses(path), kitti::defaultCalibration());
      break;
    case 4:
      kitti::oxtsToLidarPoses(kitti::readOxts(path), kitti::defaultCalibration());
      break;
    case 5:
      useLabels(io::readPerClassCsvDetections(path), true);
      break;
    case 6:
      kitti::readVelodyne(path);
      break;
    case 7: {
      io::SequenceDetections d;
      io::readDetectionCache(path, "fuzz", &d);
      break;
    }
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size < 1) return 0;
  const fuzz::TempFile file(".txt", data + 1, size - 1);
  try {
    read(data[0], file.path());
  } catch (const std::runtime_error& e) {
    fuzz::expectNamesFile(e, file.path());  // the documented refusal
  } catch (const std::exception& e) {
    fuzz::unexpectedException("reader", e);
  }
  return 0;
}
