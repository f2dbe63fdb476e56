// Statistics to compare simulated scans with real ones (docs/SIMULATOR.md, docs/sim_realism.png): histograms of
// range, intensity, points per ring, height above the ground, zero-intensity returns, local height scatter per BEV cell
// and points per occupied BEV cell above the ground, the points on each labelled car against its distance, and the
// Wasserstein-1 distance between two such histograms. Works on any KITTI
// layout the io layer reads (tracking, object, or a folder of .bin scans). Real KITTI scans carry no ring: it is
// estimated as the beam of the sensor model whose elevation is nearest the point's.
#pragma once

#include <string>
#include <vector>

#include "ret3d/core/types.h"
#include "ret3d/sim/sensor_model.h"

namespace ret3d {
namespace sim {

struct ScanStats {
  std::size_t frames = 0, points = 0;
  std::vector<double> range_hist;      // 1 m bins from 0 m (points per frame)
  std::vector<double> intensity_hist;  // 0.02 bins over [0, 1] (points per frame)
  std::vector<double> ring_hist;       // points per ring per frame
  std::vector<double> height_hist;     // 0.1 m bins of z + mount_height from -1 m (the ground of a flat road at 0)
  std::vector<double> zero_hist;       // [returns with intensity 0, other returns] per frame
  // Per BEV cell (kBevCell) within 40 m holding >= 5 points: the standard deviation of z, 0.05 m bins. Walls and
  // ground give small values, poles, trunks and vegetation (vertically spread returns) large ones.
  std::vector<double> scatter_hist;
  // Per BEV cell 10-40 m away holding points more than 0.3 m above the ground: how many (bin i = i + 1 points, the
  // last bin holds the rest). Sparse cells are where detectors put false positives on clutter.
  std::vector<double> cell_points_hist;
  std::vector<std::pair<double, std::uint32_t>> cars;  // (distance, points in box) per labelled Car
  double mean_intensity = 0;

  void add(const PointCloud& cloud, const SensorModel& sensor, const std::vector<Box>& car_boxes);
  void finish();                       // turns sums into per-frame averages
  // Median points on cars whose distance is within [lo, hi] (0 when none).
  double medianCarPoints(double lo, double hi) const;
  // Writes PREFIX_{range,intensity,rings,height,zero,scatter,cellpoints}.dat (bin centre, per frame, fraction) and
  // PREFIX_cars.dat (gnuplot columns).
  void write(const std::string& prefix) const;
};

constexpr double kBevCell = 0.5;  // m, BEV cell of the scatter and cell-points statistics

// Adds the scans of the dataset at `root` (at most `max_frames` of them; labels used when present) to `stats`.
void addDataset(ScanStats& stats, const std::string& root, const SensorModel& sensor, int max_frames = 200);
// Stats of one dataset (addDataset, then finish).
ScanStats datasetStats(const std::string& root, const SensorModel& sensor, int max_frames = 200);

// Wasserstein-1 (earth mover's) distance between two histograms over the same ascending bin centres, each normalised
// to sum 1: the integral of |CDF_a - CDF_b| over the centres, in the centres' unit. Throws on mismatched sizes, or
// when a histogram is empty or sums to zero.
double wasserstein1(const std::vector<double>& centres, const std::vector<double>& a, const std::vector<double>& b);

// The statistics `ret3d sim --compare` measures, with their .dat suffixes and units.
struct StatDistance {
  std::string name, unit;
  double w1 = 0;
};
// W1 between the .dat histograms written by ScanStats::write under two prefixes, per statistic (NaN when one of the
// two histograms is empty); throws naming the file when one is missing or malformed.
std::vector<StatDistance> compareStats(const std::string& prefix_a, const std::string& prefix_b);

}  // namespace sim
}  // namespace ret3d
