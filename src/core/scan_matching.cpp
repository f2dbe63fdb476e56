#include "ret3d/core/scan_matching.h"

#include <array>
#include <cmath>
#include <cstdint>
#include <stdexcept>
#include <unordered_map>
#include <vector>

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>
#include <Eigen/Geometry>

#include "scan_matching_points.h"
#include "ret3d/core/enum_names.h"

namespace ret3d {
namespace scan_matching {
namespace {

// 21 bits per axis; cellOf keeps each index (and its neighbours) within them, so the shifts never overflow.
std::uint64_t voxelKey(int x, int y, int z) {
  constexpr std::int64_t kOffset = 1 << 20;
  return (static_cast<std::uint64_t>(x + kOffset) << 42) | (static_cast<std::uint64_t>(y + kOffset) << 21) |
         static_cast<std::uint64_t>(z + kOffset);
}

// Clamped before the cast: a diverged estimate or a garbage return (1e30) does not fit an int (UB).
Eigen::Vector3i cellOf(const Eigen::Vector3d& p, double size) {
  auto cell = [size](double v) { return static_cast<int>(std::fmax(-1e6, std::fmin(1e6, std::floor(v / size)))); };
  return {cell(p.x()), cell(p.y()), cell(p.z())};
}

}  // namespace

// One centroid per voxel of the non-ground points within range.
Points downsample(const PointCloud& cloud, const ScanMatchingOptions& o) {
  std::unordered_map<std::uint64_t, std::pair<Eigen::Vector3d, int>> cells;
  for (const Point& p : cloud.points) {
    if (p.z < o.ground_height || std::hypot(p.x, p.y) > o.max_range) continue;
    const Eigen::Vector3d v(p.x, p.y, p.z);
    const Eigen::Vector3i c = cellOf(v, o.voxel_size);
    // emplace, not operator[]: a default Eigen vector is uninitialised.
    auto& cell =
        cells.emplace(voxelKey(c.x(), c.y(), c.z()), std::make_pair(Eigen::Vector3d::Zero().eval(), 0)).first->second;
    cell.first += v, ++cell.second;
  }
  Points out;
  out.reserve(cells.size());
  for (const auto& [key, cell] : cells) out.push_back(cell.first / cell.second);
  return out;
}

Eigen::Isometry3d planar(double x, double y, double yaw) {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  T.translation() = Eigen::Vector3d(x, y, 0);
  return T;
}

Eigen::Isometry3d planarPart(const Eigen::Isometry3d& T) {
  const Eigen::Matrix3d R = T.linear();
  return planar(T.translation().x(), T.translation().y(), std::atan2(R(1, 0), R(0, 0)));
}

namespace {

// Points hashed by cells as large as the search radius, so a neighbour lies in the 27 cells around the query.
class VoxelHash {
 public:
  VoxelHash(const Points& points, double radius) : points_(points), radius_(radius) {
    for (std::size_t i = 0; i < points.size(); ++i) {
      const Eigen::Vector3i c = cellOf(points[i], radius);
      cells_[voxelKey(c.x(), c.y(), c.z())].push_back(i);
    }
  }
  // Indices of the points within the radius.
  std::vector<std::size_t> within(const Eigen::Vector3d& q) const {
    std::vector<std::size_t> out;
    const Eigen::Vector3i c = cellOf(q, radius_);
    for (int dx = -1; dx <= 1; ++dx)
      for (int dy = -1; dy <= 1; ++dy)
        for (int dz = -1; dz <= 1; ++dz) {
          const auto it = cells_.find(voxelKey(c.x() + dx, c.y() + dy, c.z() + dz));
          if (it == cells_.end()) continue;
          for (const std::size_t i : it->second)
            if ((points_[i] - q).squaredNorm() <= radius_ * radius_) out.push_back(i);
        }
    return out;
  }
  // Index of the nearest point within the radius, or -1.
  long nearest(const Eigen::Vector3d& q) const {
    const Eigen::Vector3i c = cellOf(q, radius_);
    long best = -1;
    double best_d2 = radius_ * radius_;
    for (int dx = -1; dx <= 1; ++dx)
      for (int dy = -1; dy <= 1; ++dy)
        for (int dz = -1; dz <= 1; ++dz) {
          const auto it = cells_.find(voxelKey(c.x() + dx, c.y() + dy, c.z() + dz));
          if (it == cells_.end()) continue;
          for (const std::size_t i : it->second) {
            const double d2 = (points_[i] - q).squaredNorm();
            if (d2 < best_d2) best_d2 = d2, best = static_cast<long>(i);
          }
        }
    return best;
  }

 private:
  const Points& points_;
  double radius_;
  std::unordered_map<std::uint64_t, std::vector<std::size_t>> cells_;
};

// The surface normal at each point (the least-variance direction of its neighbours within `radius`); zero where too
// few neighbours say nothing about a surface.
std::vector<Eigen::Vector3d> normals(const Points& points, double radius) {
  const VoxelHash hash(points, radius);
  std::vector<Eigen::Vector3d> out(points.size(), Eigen::Vector3d::Zero());
  for (std::size_t i = 0; i < points.size(); ++i) {
    const std::vector<std::size_t> nb = hash.within(points[i]);
    if (nb.size() < 5) continue;
    Eigen::Vector3d mean = Eigen::Vector3d::Zero();
    for (const std::size_t j : nb) mean += points[j];
    mean /= static_cast<double>(nb.size());
    Eigen::Matrix3d cov = Eigen::Matrix3d::Zero();
    for (const std::size_t j : nb) cov += (points[j] - mean) * (points[j] - mean).transpose();
    const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(cov);
    out[i] = eig.eigenvectors().col(0);  // eigenvalues ascending
  }
  return out;
}

}  // namespace

ScanMatch matchIcp(const PointCloud& source, const PointCloud& target, const Eigen::Isometry3d& initial,
                   const ScanMatchingOptions& o) {
  const Points src = downsample(source, o), dst = downsample(target, o);
  // Point-to-plane (Chen & Medioni 1992): points may slide along walls, so a street seen from two places along it
  // does not pull the motion towards zero as point-to-point does.
  const std::vector<Eigen::Vector3d> dst_normals = normals(dst, 2.5 * o.voxel_size);
  ScanMatch result;
  // Start from the initial guess projected on the ground plane.
  Eigen::Isometry3d T = planarPart(initial);
  for (int stage = 0; stage < o.stages; ++stage) {
    const double radius = o.stages > 1 ? o.first_distance * std::pow(o.last_distance / o.first_distance,
                                                                      static_cast<double>(stage) / (o.stages - 1))
                                       : o.last_distance;
    const VoxelHash hash(dst, radius);
    for (int it = 0; it < o.iterations; ++it) {
      // Gauss-Newton on (tx, ty, yaw) about the current estimate: residual n . (p' - q), p' = T p.
      Eigen::Matrix3d H = Eigen::Matrix3d::Zero();
      Eigen::Vector3d g = Eigen::Vector3d::Zero();
      int n = 0;
      double sq = 0;
      for (const Eigen::Vector3d& p : src) {
        const Eigen::Vector3d q = T * p;
        const long j = hash.nearest(q);
        if (j < 0) continue;
        const Eigen::Vector3d& nj = dst_normals[static_cast<std::size_t>(j)];
        if (nj.isZero()) continue;
        const Eigen::Vector3d& d = dst[static_cast<std::size_t>(j)];
        const double r = nj.dot(q - d);
        const Eigen::Vector3d J(nj.x(), nj.y(), nj.y() * q.x() - nj.x() * q.y());
        H += J * J.transpose();
        g += J * r;
        sq += r * r;
        ++n;
      }
      result.correspondences = n;
      result.rmse = n ? std::sqrt(sq / n) : 0;
      if (n < o.min_correspondences) break;
      const Eigen::Vector3d delta = H.ldlt().solve(-g);
      if (!delta.allFinite()) break;
      T = planar(delta.x(), delta.y(), delta.z()) * T;
      if (delta.head<2>().norm() + std::abs(delta.z()) < 1e-5) break;
    }
  }
  result.converged = result.correspondences >= o.min_correspondences;
  result.source_to_target = T;
  return result;
}

}  // namespace scan_matching

namespace {
constexpr std::array<const char*, 2> kScanMatcherNames = {"icp", "gicp"};
static_assert(kScanMatcherNames.size() == static_cast<std::size_t>(ScanMatcher::Gicp) + 1);
}  // namespace

const char* scanMatcherName(ScanMatcher matcher) { return enumName(matcher, kScanMatcherNames); }

ScanMatcher parseScanMatcher(const std::string& name) {
  for (std::size_t i = 0; i < kScanMatcherNames.size(); ++i)
    if (name == kScanMatcherNames[i]) return static_cast<ScanMatcher>(i);
  throw std::invalid_argument("unknown scan matcher '" + name + "' (icp or gicp)");
}

ScanMatch matchScans(const PointCloud& source, const PointCloud& target, const Eigen::Isometry3d& initial,
                     const ScanMatchingOptions& options) {
  return options.matcher == ScanMatcher::Gicp ? scan_matching::matchGicp(source, target, initial, options)
                                              : scan_matching::matchIcp(source, target, initial, options);
}

}  // namespace ret3d
