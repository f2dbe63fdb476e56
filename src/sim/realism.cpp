#include "ret3d/sim/realism.h"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <stdexcept>

#include "ret3d/core/geometry.h"
#include "ret3d/io/kitti.h"

namespace ret3d {
namespace sim {

namespace fs = std::filesystem;

void ScanStats::add(const PointCloud& cloud, const SensorModel& sensor, const std::vector<Box>& car_boxes) {
  if (range_hist.empty()) {
    range_hist.assign(100, 0);
    intensity_hist.assign(50, 0);
    ring_hist.assign(static_cast<std::size_t>(sensor.beams()), 0);
  }
  ++frames;
  for (std::size_t i = 0; i < cloud.size(); ++i) {
    const Point& p = cloud.points[i];
    const double h = std::hypot(p.x, p.y), r = std::sqrt(h * h + p.z * p.z);
    if (!std::isfinite(r)) continue;
    ++points;
    range_hist[std::min<std::size_t>(static_cast<std::size_t>(r), range_hist.size() - 1)] += 1;
    intensity_hist[std::min<std::size_t>(static_cast<std::size_t>(p.intensity * 50), intensity_hist.size() - 1)] += 1;
    mean_intensity += p.intensity;
    std::size_t ring;
    if (cloud.hasRing()) {
      ring = cloud.ring[i];
    } else {
      ring = static_cast<std::size_t>(std::max(0, nearestBeam(sensor, std::atan2(p.z, h) * 180.0 / M_PI)));
    }
    if (ring < ring_hist.size()) ring_hist[ring] += 1;
  }
  const auto counts = countPointsInBoxes(car_boxes, cloud);
  for (std::size_t i = 0; i < car_boxes.size(); ++i) cars.emplace_back(std::hypot(car_boxes[i].x, car_boxes[i].y), counts[i]);
}

void ScanStats::finish() {
  if (frames == 0) return;
  for (auto* h : {&range_hist, &intensity_hist, &ring_hist})
    for (double& v : *h) v /= static_cast<double>(frames);
  if (points) mean_intensity /= static_cast<double>(points);
}

double ScanStats::medianCarPoints(double lo, double hi) const {
  std::vector<double> v;
  for (const auto& [d, n] : cars)
    if (d >= lo && d <= hi) v.push_back(n);
  if (v.empty()) return 0;
  std::sort(v.begin(), v.end());
  return v.size() % 2 ? v[v.size() / 2] : 0.5 * (v[v.size() / 2 - 1] + v[v.size() / 2]);
}

void ScanStats::write(const std::string& prefix) const {
  const fs::path parent = fs::path(prefix).parent_path();
  if (!parent.empty()) fs::create_directories(parent);
  auto open = [&](const std::string& suffix) {
    std::ofstream f(prefix + suffix);
    if (!f) throw std::runtime_error("cannot write " + prefix + suffix);
    return f;
  };
  {
    auto f = open("_range.dat");
    f << "# range_m points_per_frame fraction\n";
    for (std::size_t i = 0; i < range_hist.size(); ++i)
      f << i + 0.5 << " " << range_hist[i] << " " << (points ? range_hist[i] * frames / points : 0.0) << "\n";
  }
  {
    auto f = open("_intensity.dat");
    f << "# intensity points_per_frame fraction\n";
    for (std::size_t i = 0; i < intensity_hist.size(); ++i)
      f << (i + 0.5) / 50.0 << " " << intensity_hist[i] << " " << (points ? intensity_hist[i] * frames / points : 0.0) << "\n";
  }
  {
    auto f = open("_rings.dat");
    f << "# ring points_per_frame\n";
    for (std::size_t i = 0; i < ring_hist.size(); ++i) f << i << " " << ring_hist[i] << "\n";
  }
  {
    auto f = open("_cars.dat");
    f << "# distance_m points_in_box\n";
    for (const auto& [d, n] : cars) f << d << " " << n << "\n";
  }
}

ScanStats datasetStats(const std::string& root, const SensorModel& sensor, int max_frames) {
  ScanStats s;
  auto cars = [](const std::vector<kitti::Label>& labels, const kitti::Calibration& calib, int frame) {
    std::vector<Box> out;
    for (const auto& l : labels)
      if (l.type == "Car" && (frame < 0 || l.frame == frame)) out.push_back(kitti::labelToBox(l, calib));
    return out;
  };
  const fs::path r(root);
  const bool tracking = fs::exists(r / "training/velodyne") ? fs::is_directory(r / "training/velodyne") &&
                                                                  !fs::is_empty(r / "training/velodyne") &&
                                                                  fs::is_directory(fs::directory_iterator(r / "training/velodyne")->path())
                                                            : false;
  if (tracking) {
    kitti::TrackingDataset ds(root);
    for (const auto& seq : ds.sequences()) {
      std::vector<kitti::Label> labels;
      kitti::Calibration calib;
      if (ds.hasLabels(seq)) {
        labels = kitti::readTrackingLabels(ds.labelPath(seq));
        calib = kitti::readCalibration(ds.calibPath(seq));
      }
      for (int f : ds.frames(seq)) {
        if (static_cast<int>(s.frames) >= max_frames) break;
        s.add(kitti::readVelodyne(ds.velodynePath(seq, f)), sensor, cars(labels, calib, f));
      }
    }
  } else if (fs::exists(r / "training/label_2") || fs::exists(r / "label_2")) {
    kitti::ObjectDataset ds(root);
    for (const auto& f : ds.frames()) {
      if (static_cast<int>(s.frames) >= max_frames) break;
      const auto calib = kitti::readCalibration(ds.calibPath(f));
      s.add(kitti::readVelodyne(ds.velodynePath(f)), sensor, cars(kitti::readObjectLabels(ds.labelPath(f)), calib, -1));
    }
  } else {
    std::vector<fs::path> bins;
    for (const auto& e : fs::directory_iterator(r))
      if (e.path().extension() == ".bin") bins.push_back(e.path());
    std::sort(bins.begin(), bins.end());
    for (const auto& b : bins) {
      if (static_cast<int>(s.frames) >= max_frames) break;
      s.add(kitti::readVelodyne(b.string()), sensor, {});
    }
  }
  if (s.frames == 0) throw std::runtime_error(root + ": no scans found");
  s.finish();
  return s;
}

}  // namespace sim
}  // namespace ret3d
