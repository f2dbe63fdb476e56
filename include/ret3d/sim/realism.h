// Statistics to compare simulated scans with real ones (docs/SIMULATOR.md, docs/sim_realism.png): histograms of
// range, intensity and points per ring, and the points on each labelled car against its distance. Works on any KITTI
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
  std::vector<std::pair<double, std::uint32_t>> cars;  // (distance, points in box) per labelled Car
  double mean_intensity = 0;

  void add(const PointCloud& cloud, const SensorModel& sensor, const std::vector<Box>& car_boxes);
  void finish();                       // turns sums into per-frame averages
  // Median points on cars whose distance is within [lo, hi] (0 when none).
  double medianCarPoints(double lo, double hi) const;
  // Writes PREFIX_range.dat, PREFIX_intensity.dat, PREFIX_rings.dat, PREFIX_cars.dat (gnuplot columns).
  void write(const std::string& prefix) const;
};

// Stats of the dataset at `root` (at most `max_frames` frames; labels used when present).
ScanStats datasetStats(const std::string& root, const SensorModel& sensor, int max_frames = 200);

}  // namespace sim
}  // namespace ret3d
