#include "ret3d/sim/realism.h"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <stdexcept>
#include <unordered_map>

#include "ret3d/core/geometry.h"
#include "ret3d/core/stats.h"
#include "ret3d/io/kitti.h"

namespace ret3d {
namespace sim {

namespace fs = std::filesystem;

void ScanStats::add(const PointCloud& cloud, const SensorModel& sensor, const std::vector<Box>& car_boxes) {
  if (range_hist.empty()) {
    range_hist.assign(100, 0);
    intensity_hist.assign(50, 0);
    ring_hist.assign(static_cast<std::size_t>(sensor.beams()), 0);
    height_hist.assign(60, 0);
    zero_hist.assign(2, 0);
    scatter_hist.assign(40, 0);
    cell_points_hist.assign(50, 0);
  }
  ++frames;
  // Per BEV cell: points, sum z, sum z^2 (within 40 m), and points above the ground (10-40 m).
  struct Cell {
    double n = 0, sz = 0, szz = 0, above = 0;
  };
  std::unordered_map<std::int64_t, Cell> cells;
  cells.reserve(cloud.size() / 4);
  for (std::size_t i = 0; i < cloud.size(); ++i) {
    const Point& p = cloud.points[i];
    const double h = std::hypot(p.x, p.y), r = std::sqrt(h * h + p.z * p.z);
    if (!std::isfinite(r)) continue;
    ++points;
    // Clamped as doubles before the cast: a negative, NaN or huge value does not fit a size_t (UB).
    auto bin = [](double v, const std::vector<double>& hist) {
      return static_cast<std::size_t>(std::fmax(0.0, std::fmin(v, static_cast<double>(hist.size() - 1))));
    };
    range_hist[bin(r, range_hist)] += 1;
    intensity_hist[bin(p.intensity * 50.0, intensity_hist)] += 1;
    mean_intensity += p.intensity;
    zero_hist[p.intensity < 1e-3f ? 0 : 1] += 1;
    const double height = p.z + sensor.mount_height;
    height_hist[static_cast<std::size_t>(std::clamp((height + 1.0) / 0.1, 0.0, height_hist.size() - 1.0))] += 1;
    if (h < 40.0) {
      const auto ix = static_cast<std::int64_t>(std::floor(p.x / kBevCell)) + (1 << 20);
      const auto iy = static_cast<std::int64_t>(std::floor(p.y / kBevCell)) + (1 << 20);
      Cell& c = cells[(ix << 21) | iy];
      c.n += 1;
      c.sz += p.z;
      c.szz += static_cast<double>(p.z) * p.z;
      if (h >= 10.0 && height > 0.3) c.above += 1;
    }
    std::size_t ring;
    if (cloud.hasRing()) {
      ring = cloud.ring[i];
    } else {
      ring = static_cast<std::size_t>(std::max(0, nearestBeam(sensor, std::atan2(p.z, h) * 180.0 / M_PI)));
    }
    if (ring < ring_hist.size()) ring_hist[ring] += 1;
  }
  for (const auto& [key, c] : cells) {
    if (c.n >= 5) {
      const double sd = std::sqrt(std::max(0.0, c.szz / c.n - (c.sz / c.n) * (c.sz / c.n)));
      scatter_hist[std::min<std::size_t>(static_cast<std::size_t>(sd / 0.05), scatter_hist.size() - 1)] += 1;
    }
    if (c.above > 0)
      cell_points_hist[std::min<std::size_t>(static_cast<std::size_t>(c.above) - 1, cell_points_hist.size() - 1)] += 1;
  }
  const auto counts = countPointsInBoxes(car_boxes, cloud);
  for (std::size_t i = 0; i < car_boxes.size(); ++i) cars.emplace_back(std::hypot(car_boxes[i].x, car_boxes[i].y), counts[i]);
}

void ScanStats::finish() {
  if (frames == 0) return;
  for (auto* h : {&range_hist, &intensity_hist, &ring_hist, &height_hist, &zero_hist, &scatter_hist, &cell_points_hist})
    for (double& v : *h) v /= static_cast<double>(frames);
  if (points) mean_intensity /= static_cast<double>(points);
}

double ScanStats::medianCarPoints(double lo, double hi) const {
  std::vector<double> v;
  for (const auto& [d, n] : cars)
    if (d >= lo && d <= hi) v.push_back(n);
  return median(std::move(v));
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
  // Bin centre, per frame, fraction of the histogram's total.
  auto hist = [&](const std::string& suffix, const std::string& header, const std::vector<double>& h, double first,
                  double step) {
    auto f = open(suffix);
    double total = 0;
    for (double v : h) total += v;
    f << "# " << header << " per_frame fraction\n";
    for (std::size_t i = 0; i < h.size(); ++i)
      f << first + step * i << " " << h[i] << " " << (total > 0 ? h[i] / total : 0.0) << "\n";
  };
  hist("_height.dat", "height_above_ground_m", height_hist, -0.95, 0.1);
  hist("_zero.dat", "zero_intensity(0)_or_not(1)", zero_hist, 0, 1);
  hist("_scatter.dat", "z_stddev_per_bev_cell_m", scatter_hist, 0.025, 0.05);
  hist("_cellpoints.dat", "points_above_0.3m_per_bev_cell_10_40m", cell_points_hist, 1, 1);
  {
    auto f = open("_cars.dat");
    f << "# distance_m points_in_box\n";
    for (const auto& [d, n] : cars) f << d << " " << n << "\n";
  }
}

void addDataset(ScanStats& s, const std::string& root, const SensorModel& sensor, int max_frames) {
  const std::size_t frames0 = s.frames;
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
        if (static_cast<int>(s.frames - frames0) >= max_frames) break;
        s.add(kitti::readVelodyne(ds.velodynePath(seq, f)), sensor, cars(labels, calib, f));
      }
    }
  } else if (fs::exists(r / "training/label_2") || fs::exists(r / "label_2")) {
    kitti::ObjectDataset ds(root);
    for (const auto& f : ds.frames()) {
      if (static_cast<int>(s.frames - frames0) >= max_frames) break;
      const auto calib = kitti::readCalibration(ds.calibPath(f));
      s.add(kitti::readVelodyne(ds.velodynePath(f)), sensor, cars(kitti::readObjectLabels(ds.labelPath(f)), calib, -1));
    }
  } else {
    std::vector<fs::path> bins;
    for (const auto& e : fs::directory_iterator(r))
      if (e.path().extension() == ".bin") bins.push_back(e.path());
    std::sort(bins.begin(), bins.end());
    for (const auto& b : bins) {
      if (static_cast<int>(s.frames - frames0) >= max_frames) break;
      s.add(kitti::readVelodyne(b.string()), sensor, {});
    }
  }
  if (s.frames == frames0) throw std::runtime_error(root + ": no scans found");
}

ScanStats datasetStats(const std::string& root, const SensorModel& sensor, int max_frames) {
  ScanStats s;
  addDataset(s, root, sensor, max_frames);
  s.finish();
  return s;
}

double wasserstein1(const std::vector<double>& centres, const std::vector<double>& a, const std::vector<double>& b) {
  if (centres.empty() || a.size() != centres.size() || b.size() != centres.size())
    throw std::runtime_error("wasserstein1: histograms of " + std::to_string(a.size()) + " and " +
                             std::to_string(b.size()) + " bins over " + std::to_string(centres.size()) + " centres");
  double sa = 0, sb = 0;
  for (std::size_t i = 0; i < a.size(); ++i) {
    sa += a[i];
    sb += b[i];
  }
  if (!(sa > 0) || !(sb > 0)) throw std::runtime_error("wasserstein1: a histogram sums to zero");
  double ca = 0, cb = 0, w = 0;
  for (std::size_t i = 0; i + 1 < centres.size(); ++i) {
    ca += a[i] / sa;
    cb += b[i] / sb;
    w += std::abs(ca - cb) * (centres[i + 1] - centres[i]);
  }
  return w;
}

namespace {

// Columns 1 (bin centre) and 2 (per frame) of a .dat histogram.
void readDat(const std::string& path, std::vector<double>* centres, std::vector<double>* values) {
  std::ifstream f(path);
  if (!f) throw std::runtime_error("cannot read " + path + " (written by ret3d sim --stats)");
  std::string line;
  int n = 0;
  while (std::getline(f, line)) {
    ++n;
    if (line.empty() || line[0] == '#') continue;
    std::istringstream s(line);
    double c = 0, v = 0;
    if (!(s >> c >> v)) throw std::runtime_error(path + ":" + std::to_string(n) + ": expected two numbers");
    centres->push_back(c);
    values->push_back(v);
  }
}

}  // namespace

std::vector<StatDistance> compareStats(const std::string& prefix_a, const std::string& prefix_b) {
  const std::vector<std::pair<std::string, std::string>> stats = {
      {"range", "m"},   {"intensity", ""},  {"rings", "rings"},          {"height", "m"},
      {"zero", ""},     {"scatter", "m"},   {"cellpoints", "points"}};
  std::vector<StatDistance> out;
  for (const auto& [name, unit] : stats) {
    std::vector<double> ca, a, cb, b;
    readDat(prefix_a + "_" + name + ".dat", &ca, &a);
    readDat(prefix_b + "_" + name + ".dat", &cb, &b);
    if (ca != cb)
      throw std::runtime_error(prefix_a + "_" + name + ".dat and " + prefix_b + "_" + name + ".dat: different bins");
    double sa = 0, sb = 0;
    for (double v : a) sa += v;
    for (double v : b) sb += v;
    // An empty histogram (no cell of that kind in either data) has no distance.
    out.push_back({name, unit, sa > 0 && sb > 0 ? wasserstein1(ca, a, b) : std::nan("")});
  }
  return out;
}

}  // namespace sim
}  // namespace ret3d
