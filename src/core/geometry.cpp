#include "ret3d/core/geometry.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <unordered_map>

namespace ret3d {

double wrapAngle(double a) {
  if (!std::isfinite(a)) return a;
  a = std::fmod(a, 2.0 * M_PI);  // (-2pi, 2pi)
  if (a <= -M_PI) a += 2.0 * M_PI;
  if (a > M_PI) a -= 2.0 * M_PI;
  return a;
}

std::array<Eigen::Vector2d, 4> bevCorners(const Box& b) {
  const double c = std::cos(b.yaw), s = std::sin(b.yaw);
  const double hl = 0.5 * b.length, hw = 0.5 * b.width;
  // Local corners, counter-clockwise from front-left: (+l, +w), (-l, +w), (-l, -w), (+l, -w).
  const double lx[4] = {hl, -hl, -hl, hl};
  const double ly[4] = {hw, hw, -hw, -hw};
  std::array<Eigen::Vector2d, 4> out;
  for (int i = 0; i < 4; ++i) {
    out[i] = Eigen::Vector2d(b.x + c * lx[i] - s * ly[i], b.y + s * lx[i] + c * ly[i]);
  }
  return out;
}

std::array<Eigen::Vector3d, 8> boxCorners(const Box& b) {
  const auto bev = bevCorners(b);
  std::array<Eigen::Vector3d, 8> out;
  for (int i = 0; i < 4; ++i) {
    out[i] = Eigen::Vector3d(bev[i].x(), bev[i].y(), b.bottom());
    out[i + 4] = Eigen::Vector3d(bev[i].x(), bev[i].y(), b.top());
  }
  return out;
}

double polygonArea(const std::vector<Eigen::Vector2d>& poly) {
  const std::size_t n = poly.size();
  if (n < 3) return 0.0;
  double a = 0.0;
  for (std::size_t i = 0; i < n; ++i) {
    const auto& p = poly[i];
    const auto& q = poly[(i + 1) % n];
    a += p.x() * q.y() - q.x() * p.y();
  }
  return 0.5 * a;
}

namespace {
// Cross product of (b - a) x (p - a): > 0 when p is left of the directed edge a -> b.
inline double side(const Eigen::Vector2d& a, const Eigen::Vector2d& b, const Eigen::Vector2d& p) {
  return (b.x() - a.x()) * (p.y() - a.y()) - (b.y() - a.y()) * (p.x() - a.x());
}
}  // namespace

std::vector<Eigen::Vector2d> convexIntersection(const std::vector<Eigen::Vector2d>& a,
                                                const std::vector<Eigen::Vector2d>& b) {
  // Sutherland-Hodgman: clip `a` by each edge of `b`. Points on an edge count as inside, so touching and
  // collinear edges give a degenerate (zero-area) polygon rather than a spurious one.
  std::vector<Eigen::Vector2d> out = a;
  const std::size_t m = b.size();
  for (std::size_t j = 0; j < m && !out.empty(); ++j) {
    const Eigen::Vector2d& e0 = b[j];
    const Eigen::Vector2d& e1 = b[(j + 1) % m];
    // Scale-aware tolerance so that points exactly on the edge (up to rounding) are treated as on it.
    const double tol = 1e-12 * std::max(1.0, (e1 - e0).squaredNorm());
    std::vector<Eigen::Vector2d> in;
    in.swap(out);
    const std::size_t n = in.size();
    for (std::size_t i = 0; i < n; ++i) {
      const Eigen::Vector2d& p = in[i];
      const Eigen::Vector2d& q = in[(i + 1) % n];
      const double sp = side(e0, e1, p), sq = side(e0, e1, q);
      const bool p_in = sp >= -tol, q_in = sq >= -tol;
      if (p_in) out.push_back(p);
      if (p_in != q_in) {
        const double t = sp / (sp - sq);
        out.push_back(p + t * (q - p));
      }
    }
  }
  return out;
}

double bevIntersectionArea(const Box& a, const Box& b) {
  // Quick reject by circumscribed circles.
  const double ra = 0.5 * std::hypot(a.length, a.width), rb = 0.5 * std::hypot(b.length, b.width);
  const double dx = a.x - b.x, dy = a.y - b.y;
  if (dx * dx + dy * dy > (ra + rb) * (ra + rb)) return 0.0;
  const auto ca = bevCorners(a), cb = bevCorners(b);
  const std::vector<Eigen::Vector2d> pa(ca.begin(), ca.end()), pb(cb.begin(), cb.end());
  return std::max(0.0, polygonArea(convexIntersection(pa, pb)));
}

double bevIoU(const Box& a, const Box& b) {
  const double inter = bevIntersectionArea(a, b);
  const double uni = a.length * a.width + b.length * b.width - inter;
  return uni > 0.0 ? std::clamp(inter / uni, 0.0, 1.0) : 0.0;
}

double iou3d(const Box& a, const Box& b) {
  const double dz = std::min(a.top(), b.top()) - std::max(a.bottom(), b.bottom());
  if (dz <= 0.0) return 0.0;
  const double inter = bevIntersectionArea(a, b) * dz;
  const double uni = a.length * a.width * a.height + b.length * b.width * b.height - inter;
  return uni > 0.0 ? std::clamp(inter / uni, 0.0, 1.0) : 0.0;
}

double iou2d(const std::array<double, 4>& a, const std::array<double, 4>& b) {
  const double iw = std::min(a[2], b[2]) - std::max(a[0], b[0]);
  const double ih = std::min(a[3], b[3]) - std::max(a[1], b[1]);
  if (iw <= 0.0 || ih <= 0.0) return 0.0;
  const double inter = iw * ih;
  const double uni = (a[2] - a[0]) * (a[3] - a[1]) + (b[2] - b[0]) * (b[3] - b[1]) - inter;
  return uni > 0.0 ? inter / uni : 0.0;
}

bool pointInBox(const Box& b, const Eigen::Vector3d& p) {
  const double dz = p.z() - b.z;
  if (std::abs(dz) > 0.5 * b.height) return false;
  const double c = std::cos(b.yaw), s = std::sin(b.yaw);
  const double dx = p.x() - b.x, dy = p.y() - b.y;
  const double lx = c * dx + s * dy, ly = -s * dx + c * dy;
  return std::abs(lx) <= 0.5 * b.length && std::abs(ly) <= 0.5 * b.width;
}

bool BevWedge::contains(const Eigen::Vector2d& p) const {
  auto cross = [](const Eigen::Vector2d& u, const Eigen::Vector2d& v) { return u.x() * v.y() - u.y() * v.x(); };
  const Eigen::Vector2d d = p - apex;
  // The sign of ray_a x ray_b fixes the orientation, so a mirrored wedge (flip augmentation) tests alike.
  const double s = cross(ray_a, ray_b) >= 0 ? 1.0 : -1.0;
  if (s * cross(ray_a, d) >= 0 && s * cross(d, ray_b) >= 0) return true;
  if (margin <= 0) return false;
  // Outside a convex wedge, the distance to it is the distance to the nearer edge ray.
  auto toRay = [&](const Eigen::Vector2d& r) {
    const Eigen::Vector2d u = r.normalized();
    return d.dot(u) > 0 ? std::abs(cross(u, d)) : d.norm();
  };
  return std::min(toRay(ray_a), toRay(ray_b)) <= margin;
}

std::uint32_t countPointsInBox(const Box& b, const PointCloud& cloud) {
  std::uint32_t n = 0;
  for (const Point& p : cloud.points) {
    if (pointInBox(b, Eigen::Vector3d(p.x, p.y, p.z))) ++n;
  }
  return n;
}

std::vector<std::uint32_t> countPointsInBoxes(const std::vector<Box>& boxes, const PointCloud& cloud) {
  std::vector<std::uint32_t> counts(boxes.size(), 0);
  if (boxes.empty()) return counts;
  // Hash each box into the cells of a 2 m grid its circumscribed circle touches; each point then tests only the
  // boxes of its own cell.
  constexpr double kCell = 2.0;
  // Unsigned shift (a negative cell shifted left is UB before C++20); the cell index clamped before the cast (a
  // finite 1e30 or a NaN box does not fit an integer). Clamped cells merely share a key: pointInBox decides.
  auto cell = [](double v) { return static_cast<std::int64_t>(std::fmax(-1e9, std::fmin(1e9, std::floor(v / kCell)))); };
  auto key = [](std::int64_t ix, std::int64_t iy) {
    return (static_cast<std::uint64_t>(ix) << 32) ^ static_cast<std::uint32_t>(iy);
  };
  std::unordered_map<std::uint64_t, std::vector<std::uint32_t>> grid;
  for (std::uint32_t i = 0; i < boxes.size(); ++i) {
    const Box& b = boxes[i];
    const double r = 0.5 * std::hypot(b.length, b.width);
    const std::int64_t x0 = cell(b.x - r), x1 = cell(b.x + r), y0 = cell(b.y - r), y1 = cell(b.y + r);
    for (std::int64_t ix = x0; ix <= x1; ++ix)
      for (std::int64_t iy = y0; iy <= y1; ++iy) grid[key(ix, iy)].push_back(i);
  }
  for (const Point& p : cloud.points) {
    if (!std::isfinite(p.x) || !std::isfinite(p.y) || !std::isfinite(p.z)) continue;
    const auto it = grid.find(key(cell(p.x), cell(p.y)));
    if (it == grid.end()) continue;
    const Eigen::Vector3d q(p.x, p.y, p.z);
    for (std::uint32_t i : it->second) {
      if (pointInBox(boxes[i], q)) ++counts[i];
    }
  }
  return counts;
}

}  // namespace ret3d
