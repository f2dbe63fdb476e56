#include "ret3d/bev/bev_encoder.h"

#include <algorithm>
#include <cmath>
#include <sstream>
#include <stdexcept>
#include <thread>

namespace ret3d {

int BevGeometry::width() const { return static_cast<int>(std::lround((x_max - x_min) / resolution)); }
int BevGeometry::height() const { return static_cast<int>(std::lround((y_max - y_min) / resolution)); }

void BevGeometry::validate() const {
  auto fail = [&](const std::string& what) { throw std::invalid_argument("BEV geometry: " + what + " (" + describe() + ")"); };
  if (!(resolution > 0) || !std::isfinite(resolution)) fail("resolution must be positive");
  if (!(x_max > x_min)) fail("x_max must exceed x_min");
  if (!(y_max > y_min)) fail("y_max must exceed y_min");
  if (!(z_max > z_min)) fail("z_max must exceed z_min");
  if (std::abs((x_max - x_min) / resolution - width()) > 1e-6)
    fail("x extent is not a whole number of cells");
  if (std::abs((y_max - y_min) / resolution - height()) > 1e-6)
    fail("y extent is not a whole number of cells");
}

Eigen::Vector2d BevGeometry::metricToGrid(double x, double y) const {
  return {(x - x_min) / resolution, (y - y_min) / resolution};
}

Eigen::Vector2d BevGeometry::gridToMetric(double u, double v) const {
  return {x_min + u * resolution, y_min + v * resolution};
}

Eigen::Vector2d BevGeometry::metricToFeature(double x, double y, int stride) const {
  return metricToGrid(x, y) / static_cast<double>(stride);
}

Eigen::Vector2d BevGeometry::featureToMetric(double u, double v, int stride) const {
  return gridToMetric(u * stride, v * stride);
}

bool BevGeometry::cellOf(double x, double y, double z, int* u, int* v) const {
  if (!(x >= x_min && x < x_max && y >= y_min && y < y_max && z >= z_min && z <= z_max)) return false;
  const int cu = static_cast<int>((x - x_min) / resolution);
  const int cv = static_cast<int>((y - y_min) / resolution);
  if (cu < 0 || cu >= width() || cv < 0 || cv >= height()) return false;
  *u = cu;
  *v = cv;
  return true;
}

bool BevGeometry::operator==(const BevGeometry& o) const {
  return x_min == o.x_min && x_max == o.x_max && y_min == o.y_min && y_max == o.y_max && z_min == o.z_min &&
         z_max == o.z_max && resolution == o.resolution;
}

std::string BevGeometry::describe() const {
  std::ostringstream os;
  os << "x [" << x_min << ", " << x_max << "] y [" << y_min << ", " << y_max << "] z [" << z_min << ", " << z_max
     << "] res " << resolution << " (" << width() << " x " << height() << ")";
  return os.str();
}

BevEncoder::BevEncoder(const BevEncoderOptions& options) : options_(options) {
  options_.geometry.validate();
  if (options_.threads < 1) throw std::invalid_argument("BEV encoder: threads must be >= 1");
  if (!(options_.density_norm > 1.0)) throw std::invalid_argument("BEV encoder: density_norm must exceed 1");
}

BevImage BevEncoder::encode(const PointCloud& current, const PointCloud* previous,
                            const Eigen::Isometry3d& prev_to_current) const {
  BevImage out;
  encode(current, previous, prev_to_current, &out);
  return out;
}

namespace {

// One grid's part of an item: its geometry, the sweep's three channels and the rows [v_begin, v_end) to fill.
struct Target {
  int W, H, v_begin, v_end;
  float x_min, y_min, z_min, z_max, inv_span, inv_res;
  float *height, *count, *intensity;
};

// Accumulates the points of one sweep that fall in each target's rows: max height, count, max intensity. The previous
// sweep is moved into the current frame first (transform); each point is read and moved once for every grid. A worker
// owns a band of rows (or a whole sweep), so the threads never share a cell: no locks and no merge pass.
void accumulateSweep(const PointCloud& cloud, const Eigen::Matrix<float, 3, 4>& T, bool transform,
                     const std::vector<Target>& targets) {
  for (const Point& p : cloud.points) {
    float x = p.x, y = p.y, z = p.z;
    if (transform) {
      x = T(0, 0) * p.x + T(0, 1) * p.y + T(0, 2) * p.z + T(0, 3);
      y = T(1, 0) * p.x + T(1, 1) * p.y + T(1, 2) * p.z + T(1, 3);
      z = T(2, 0) * p.x + T(2, 1) * p.y + T(2, 2) * p.z + T(2, 3);
    }
    const float inten = std::min(1.0f, std::max(0.0f, std::isfinite(p.intensity) ? p.intensity : 0.0f));
    for (const Target& t : targets) {
      if (!(z >= t.z_min && z <= t.z_max)) continue;  // also drops NaN
      const float fu = (x - t.x_min) * t.inv_res, fv = (y - t.y_min) * t.inv_res;
      // Bounds in float before the cast: a finite but huge coordinate (1e30) does not fit an int (UB; on x86 it
      // became INT_MIN, an index far outside the image).
      if (!(fu >= 0.0f && fv >= 0.0f && fu < static_cast<float>(t.W) && fv < static_cast<float>(t.H))) continue;
      const int u = static_cast<int>(fu), v = static_cast<int>(fv);
      if (u >= t.W || v >= t.H || v < t.v_begin || v >= t.v_end) continue;
      const std::size_t idx = static_cast<std::size_t>(v) * t.W + u;
      const float h = (z - t.z_min) * t.inv_span;                      // LWD-3D eq. (1), normalised to [0, 1]
      if (h > t.height[idx]) t.height[idx] = h;
      t.count[idx] += 1.0f;
      if (inten > t.intensity[idx]) t.intensity[idx] = inten;         // LWD-3D eq. (3)
    }
  }
}

}  // namespace

void BevEncoder::encode(const PointCloud& current, const PointCloud* previous,
                        const Eigen::Isometry3d& prev_to_current, BevImage* out) const {
  encodeAll({{this, out}}, current, previous, prev_to_current);
}

void BevEncoder::encodeAll(const std::vector<std::pair<const BevEncoder*, BevImage*>>& targets,
                           const PointCloud& current, const PointCloud* previous,
                           const Eigen::Isometry3d& prev_to_current) {
  if (targets.empty()) return;
  int min_h = 1 << 30;
  for (const auto& [enc, out] : targets) {
    const BevGeometry& g = enc->options_.geometry;
    out->channels = kChannels;
    out->height = g.height();
    out->width = g.width();
    out->data.assign(static_cast<std::size_t>(out->height) * out->width * kChannels, 0.0f);
    min_h = std::min(min_h, out->height);
  }
  const Eigen::Matrix<float, 3, 4> T = prev_to_current.matrix().topRows<3>().cast<float>();

  // Work items: (sweep, band of rows); each band is the same fraction of every grid's rows, so items never write the
  // same cell. Sweeps first, so that two threads take one sweep each.
  struct Item {
    int sweep, band;
  };
  const int threads = std::max(1, std::min(targets.front().first->options_.threads, min_h));
  const int sweeps = previous ? kSweeps : 1;
  const int bands = std::max(1, threads / sweeps);
  std::vector<Item> items;
  for (int s = 0; s < sweeps; ++s)
    for (int b = 0; b < bands; ++b) items.push_back({s, b});

  auto run = [&](const Item& it) {
    std::vector<Target> parts;
    parts.reserve(targets.size());
    for (const auto& [enc, out] : targets) {
      const BevGeometry& g = enc->options_.geometry;
      const std::size_t plane = static_cast<std::size_t>(out->height) * out->width;
      float* base = out->data.data() + plane * (kChannelsPerSweep * it.sweep);
      parts.push_back({out->width, out->height, out->height * it.band / bands, out->height * (it.band + 1) / bands,
                       static_cast<float>(g.x_min), static_cast<float>(g.y_min), static_cast<float>(g.z_min),
                       static_cast<float>(g.z_max), static_cast<float>(1.0 / (g.z_max - g.z_min)),
                       static_cast<float>(1.0 / g.resolution), base, base + plane, base + 2 * plane});
    }
    accumulateSweep(it.sweep == 0 ? current : *previous, T, it.sweep == 1, parts);
    // Counts -> LWD-3D eq. (2), read as min(1, log(N + 1) / log(64)) (the printed log((N+1)/64) is negative for
    // every N < 63; MV3D's normalisation is meant), over this item's rows of each grid.
    for (std::size_t k = 0; k < parts.size(); ++k) {
      const Target& t = parts[k];
      const float inv_log_norm = static_cast<float>(1.0 / std::log(targets[k].first->options_.density_norm));
      const std::size_t end = static_cast<std::size_t>(t.v_end) * t.W;
      for (std::size_t i = static_cast<std::size_t>(t.v_begin) * t.W; i < end; ++i)
        if (t.count[i] > 0) t.count[i] = std::min(1.0f, std::log(t.count[i] + 1.0f) * inv_log_norm);
    }
  };
  auto worker = [&](int t) {
    for (std::size_t i = t; i < items.size(); i += threads) run(items[i]);
  };
  if (threads == 1) {
    worker(0);
    return;
  }
  std::vector<std::thread> pool;
  pool.reserve(threads - 1);
  for (int t = 1; t < threads; ++t) pool.emplace_back(worker, t);
  worker(0);
  for (auto& th : pool) th.join();
}

}  // namespace ret3d
