#include "ret3d/sim/scene.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "ret3d/core/geometry.h"

namespace ret3d {
namespace sim {

namespace {

using V2 = Eigen::Vector2d;

// Smooth value noise in [-1, 1] (bilinear between hashed lattice values, smoothstep weights).
double valueNoise(std::uint64_t seed, double x, double y) {
  const double fx = std::floor(x), fy = std::floor(y);
  const auto ix = static_cast<long long>(fx), iy = static_cast<long long>(fy);
  auto h = [&](long long a, long long b) {
    return static_cast<double>(mix64(seed ^ mix64(static_cast<std::uint64_t>(a) * 0x9E3779B1ULL ^
                                                  (static_cast<std::uint64_t>(b) << 32))) >> 11) *
               (2.0 / 9007199254740992.0) - 1.0;
  };
  double tx = x - fx, ty = y - fy;
  tx = tx * tx * (3 - 2 * tx);
  ty = ty * ty * (3 - 2 * ty);
  const double a = h(ix, iy), b = h(ix + 1, iy), c = h(ix, iy + 1), d = h(ix + 1, iy + 1);
  return (a * (1 - tx) + b * tx) * (1 - ty) + (c * (1 - tx) + d * tx) * ty;
}

}  // namespace

Surface drawSurface(const SimConfig& config, const std::string& material, Rng& rng) {
  auto it = config.materials.find(material);
  const MaterialConfig m = it != config.materials.end() ? it->second : MaterialConfig{};
  Surface s;
  s.reflectivity = static_cast<float>(std::clamp(rng.normal(m.reflectivity, m.sigma), 0.01, 1.0));
  s.dropout = static_cast<float>(m.dropout);
  s.porosity = static_cast<float>(m.porosity);
  return s;
}

// ---- queries ------------------------------------------------------------------------------------------------

double Scene::roadDistance(const Eigen::Vector2d& p, int* road, double* lateral) const {
  double best = std::numeric_limits<double>::infinity();
  const long cx = static_cast<long>(std::floor(p.x() / cell)), cy = static_cast<long>(std::floor(p.y() / cell));
  int found_at = -1;
  // Rings of cells outwards; one more ring after the first hit, since a nearer sample may sit there.
  for (int r = 0; r <= 4; ++r) {
    if (found_at >= 0 && r > found_at + 1) break;
    for (long ix = cx - r; ix <= cx + r; ++ix) {
      for (long iy = cy - r; iy <= cy + r; ++iy) {
        if (std::max(std::abs(ix - cx), std::abs(iy - cy)) != r) continue;
        const long long key = static_cast<long long>((static_cast<unsigned long long>(ix) << 32) ^ static_cast<unsigned long long>(iy & 0xffffffff));
        auto it = std::lower_bound(buckets.begin(), buckets.end(), key,
                                   [](const auto& b, long long k) { return b.first < k; });
        if (it == buckets.end() || it->first != key) continue;
        for (const Sample& smp : it->second) {
          const Road& rd = roads[smp.road];
          const auto& pts = rd.center.points();
          // Distance to the segments on both sides of the sample.
          for (int k = std::max(0, smp.index - 1); k <= smp.index && k + 1 < static_cast<int>(pts.size()); ++k) {
            const V2 a = pts[k], d = pts[k + 1] - a;
            const double t = std::clamp((p - a).dot(d) / std::max(d.squaredNorm(), 1e-12), 0.0, 1.0);
            const double dist = (a + t * d - p).norm();
            const double v = dist - rd.half_width;
            if (v < best) {
              best = v;
              if (found_at < 0) found_at = r;
              if (road) *road = smp.road;
              if (lateral) {
                const double cr = d.x() * (p - a).y() - d.y() * (p - a).x();
                *lateral = cr >= 0 ? dist : -dist;
              }
            }
          }
        }
      }
    }
  }
  if (!std::isfinite(best)) {
    best = 4 * cell;  // far from every road
    if (road) *road = 0;
    if (lateral) *lateral = 0;
  }
  return best;
}

double Scene::baseHeight(const Eigen::Vector2d& p) const {
  if (flat || roads.empty() || roads[0].z.empty()) return 0.0;
  const double s = roads[0].center.project(p);
  const auto& st = roads[0].center.stations();
  const std::size_t i = std::min<std::size_t>(static_cast<std::size_t>(std::lower_bound(st.begin(), st.end(), s) - st.begin()),
                                              roads[0].z.size() - 1);
  return roads[0].z[i];
}

bool Scene::onOtherCarriageway(const Eigen::Vector2d& p, int except, double margin) const {
  for (std::size_t r = 0; r < roads.size(); ++r) {
    if (static_cast<int>(r) == except) continue;
    double lat = 0;
    const double s = roads[r].center.project(p, &lat);
    if (s <= 0.0 || s >= roads[r].center.length()) continue;  // beyond the road's ends
    if (std::abs(lat) < roads[r].half_width + margin) return true;
  }
  return false;
}

double Scene::groundHeight(double x, double y) const {
  const SimConfig& c = *config;
  const V2 p(x, y);
  int road = 0;
  double lat = 0;
  const double d = roadDistance(p, &road, &lat);
  const double base = baseHeight(p);
  const double sw = roads.empty() ? 0.0 : roads[road].sidewalk;
  const double lambda = c.ground.roughness_wavelength;
  const double n = valueNoise(noise_seed, x / lambda, y / lambda) + 0.5 * valueNoise(noise_seed + 1, 2 * x / lambda, 2 * y / lambda);
  if (d < 0) return base + c.ground.road_roughness * n / 1.5;
  const double beyond = d - sw - c.ground.terrain_step;
  if (beyond <= 0) return base + c.ground.road_roughness * n / 1.5;
  const double slope = terrain_slope[lat >= 0 ? 1 : 0];
  const double rise = std::clamp(slope * beyond, -1.5, 4.0);
  return base + (sw > 0 ? c.road.curb_height : 0.0) + rise + c.ground.terrain_roughness * n / 1.5;
}

}  // namespace sim
}  // namespace ret3d
