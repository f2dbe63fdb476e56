// Point clouds to the bird's-eye-view (BEV) image the detector reads: per sweep the three channels of LWD-3D
// eqs. (1)-(3) (maximum height, density, maximum intensity), for the current sweep and the previous one moved into
// the current frame by the ego motion (so the network can see motion, as CenterPoint stacks sweeps).
#pragma once

#include <cstdint>
#include <string>
#include <utility>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "ret3d/core/types.h"

namespace ret3d {

// The metric extent of the BEV grid and the cell <-> metric transform (the "transformation matrix" LWD-3D keeps to
// turn BEV detections back into 3D boxes). Column index u runs along x, row index v along y:
//   u = floor((x - x_min) / resolution), v = floor((y - y_min) / resolution).
struct BevGeometry {
  double x_min = -48.0, x_max = 48.0;  // 360 degrees around the sensor by default
  double y_min = -48.0, y_max = 48.0;
  double z_min = -3.0, z_max = 1.0;    // points outside are dropped; height is normalised over this span
  double resolution = 0.25;            // metres per cell

  int width() const;   // cells along x
  int height() const;  // cells along y
  // Throws std::invalid_argument (naming the field) when the extent or resolution is unusable.
  void validate() const;

  // Continuous grid coordinates (cell units; cell (u, v) covers [u, u+1) x [v, v+1)) of a metric point.
  Eigen::Vector2d metricToGrid(double x, double y) const;
  // Metric position of continuous grid coordinates; the centre of cell (u, v) is gridToMetric(u + 0.5, v + 0.5).
  Eigen::Vector2d gridToMetric(double u, double v) const;
  // The same at a feature map of the given stride (one feature cell = stride grid cells).
  Eigen::Vector2d metricToFeature(double x, double y, int stride) const;
  Eigen::Vector2d featureToMetric(double u, double v, int stride) const;
  // Cell index of a metric point, or false when it lies outside the grid (x, y, z).
  bool cellOf(double x, double y, double z, int* u, int* v) const;

  bool operator==(const BevGeometry& o) const;
  bool operator!=(const BevGeometry& o) const { return !(*this == o); }
  std::string describe() const;  // "x [-48, 48] y [-48, 48] z [-3, 1] res 0.25 (384 x 384)"
};

// A C x H x W float image, row-major per channel: data[(c * H + v) * W + u].
struct BevImage {
  int channels = 0, height = 0, width = 0;
  std::vector<float> data;

  float at(int c, int v, int u) const { return data[(static_cast<std::size_t>(c) * height + v) * width + u]; }
  float& at(int c, int v, int u) { return data[(static_cast<std::size_t>(c) * height + v) * width + u]; }
};

struct BevEncoderOptions {
  BevGeometry geometry;
  int threads = 2;            // worker threads for one encoding
  double density_norm = 64.0;  // N at which the density channel saturates (LWD-3D eq. (2))
};

// Channel layout: sweep s (0 = current, 1 = previous) occupies channels 3s .. 3s+2:
//   3s + 0: max height, (max z - z_min) / (z_max - z_min)      LWD-3D eq. (1)
//   3s + 1: density, min(1, log(N + 1) / log(density_norm))    LWD-3D eq. (2)
//   3s + 2: max intensity (intensity already in [0, 1])         LWD-3D eq. (3)
// Empty cells are 0 in every channel.
class BevEncoder {
 public:
  static constexpr int kChannelsPerSweep = 3;
  static constexpr int kSweeps = 2;
  static constexpr int kChannels = kChannelsPerSweep * kSweeps;

  explicit BevEncoder(const BevEncoderOptions& options);
  const BevEncoderOptions& options() const { return options_; }
  const BevGeometry& geometry() const { return options_.geometry; }

  // Encodes the current sweep and, when given, the previous sweep moved into the current frame by prev_to_current
  // (a point p of the previous frame lies at prev_to_current * p in the current one). Without a previous sweep its
  // channels stay 0. Thread-safe (no shared mutable state).
  BevImage encode(const PointCloud& current, const PointCloud* previous = nullptr,
                  const Eigen::Isometry3d& prev_to_current = Eigen::Isometry3d::Identity()) const;
  // The same into an existing image (resized when needed), avoiding the allocation per frame.
  void encode(const PointCloud& current, const PointCloud* previous, const Eigen::Isometry3d& prev_to_current,
              BevImage* out) const;
  // Several grids of the same sweeps at once (the two-resolution detector's near and far fields): one pass over the
  // points fills every image, with the first encoder's thread count. The same images as encoding each alone.
  static void encodeAll(const std::vector<std::pair<const BevEncoder*, BevImage*>>& targets, const PointCloud& current,
                        const PointCloud* previous, const Eigen::Isometry3d& prev_to_current);

 private:
  BevEncoderOptions options_;
};

}  // namespace ret3d
