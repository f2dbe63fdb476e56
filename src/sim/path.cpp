#include "ret3d/sim/path.h"

#include <algorithm>
#include <cmath>

namespace ret3d {
namespace sim {

Path::Path(std::vector<Eigen::Vector2d> points) {
  for (const auto& p : points) {
    if (pts_.empty() || (p - pts_.back()).norm() > 1e-6) pts_.push_back(p);
  }
  rebuild();
}

void Path::rebuild() {
  s_.assign(pts_.size(), 0.0);
  for (std::size_t i = 1; i < pts_.size(); ++i) s_[i] = s_[i - 1] + (pts_[i] - pts_[i - 1]).norm();
}

PathPose Path::at(double s) const {
  if (pts_.size() < 2) return {pts_.empty() ? Eigen::Vector2d::Zero() : pts_[0], 0.0};
  s = std::clamp(s, 0.0, s_.back());
  std::size_t i = static_cast<std::size_t>(std::upper_bound(s_.begin(), s_.end(), s) - s_.begin());
  i = std::clamp<std::size_t>(i, 1, pts_.size() - 1);
  const double seg = s_[i] - s_[i - 1];
  const double t = seg > 0 ? (s - s_[i - 1]) / seg : 0.0;
  const Eigen::Vector2d d = pts_[i] - pts_[i - 1];
  PathPose out{pts_[i - 1] + t * d, std::atan2(d.y(), d.x())};
  // Blend the heading with the neighbouring segment near vertices, so turning actors rotate smoothly.
  if (t < 0.5 && i >= 2) {
    const Eigen::Vector2d dp = pts_[i - 1] - pts_[i - 2];
    double dy = std::remainder(out.yaw - std::atan2(dp.y(), dp.x()), 2 * M_PI);
    out.yaw -= (0.5 - t) * dy;
  } else if (t >= 0.5 && i + 1 < pts_.size()) {
    const Eigen::Vector2d dn = pts_[i + 1] - pts_[i];
    double dy = std::remainder(std::atan2(dn.y(), dn.x()) - out.yaw, 2 * M_PI);
    out.yaw += (t - 0.5) * dy;
  }
  out.yaw = std::remainder(out.yaw, 2 * M_PI);
  return out;
}

Path Path::offset(double d) const {
  std::vector<Eigen::Vector2d> out;
  out.reserve(pts_.size());
  for (std::size_t i = 0; i < pts_.size(); ++i) {
    Eigen::Vector2d t = pts_[std::min(i + 1, pts_.size() - 1)] - pts_[i > 0 ? i - 1 : 0];
    if (t.norm() < 1e-9) t = Eigen::Vector2d(1, 0);
    t.normalize();
    out.push_back(pts_[i] + d * Eigen::Vector2d(-t.y(), t.x()));
  }
  return Path(out);
}

Path Path::reversed() const {
  std::vector<Eigen::Vector2d> out(pts_.rbegin(), pts_.rend());
  return Path(out);
}

Path Path::slice(double s0, double s1, double step) const {
  std::vector<Eigen::Vector2d> out;
  s0 = std::clamp(s0, 0.0, length());
  s1 = std::clamp(s1, 0.0, length());
  if (s1 <= s0) return Path();
  const int n = std::max(1, static_cast<int>(std::ceil((s1 - s0) / step)));
  for (int k = 0; k <= n; ++k) out.push_back(at(s0 + (s1 - s0) * k / n).p);
  return Path(out);
}

double Path::project(const Eigen::Vector2d& q, double* lateral) const {
  double best = 1e300, best_s = 0, best_lat = 0;
  for (std::size_t i = 1; i < pts_.size(); ++i) {
    const Eigen::Vector2d a = pts_[i - 1], d = pts_[i] - a;
    const double len2 = d.squaredNorm();
    const double t = len2 > 0 ? std::clamp((q - a).dot(d) / len2, 0.0, 1.0) : 0.0;
    const double dist = (a + t * d - q).squaredNorm();
    if (dist < best) {
      best = dist;
      best_s = s_[i - 1] + t * std::sqrt(len2);
      const double cross = d.x() * (q - a).y() - d.y() * (q - a).x();
      best_lat = (cross >= 0 ? 1 : -1) * std::sqrt(dist);
    }
  }
  if (lateral) *lateral = best_lat;
  return best_s;
}

void Path::append(const Path& other) {
  for (const auto& p : other.pts_) {
    if (pts_.empty() || (p - pts_.back()).norm() > 1e-6) pts_.push_back(p);
  }
  rebuild();
}

std::vector<Eigen::Vector2d> arcPoints(const Eigen::Vector2d& p0, double yaw0, double radius, double angle,
                                       double step) {
  std::vector<Eigen::Vector2d> out;
  const double sgn = angle >= 0 ? 1.0 : -1.0;
  const Eigen::Vector2d left(-std::sin(yaw0), std::cos(yaw0));
  const Eigen::Vector2d c = p0 + sgn * radius * left;
  const int n = std::max(1, static_cast<int>(std::ceil(std::abs(angle) * radius / step)));
  for (int k = 1; k <= n; ++k) {
    const double a = angle * k / n;
    // Rotate p0 about c by a.
    const Eigen::Vector2d r = p0 - c;
    out.emplace_back(c.x() + std::cos(a) * r.x() - std::sin(a) * r.y(), c.y() + std::sin(a) * r.x() + std::cos(a) * r.y());
  }
  return out;
}

Path filletRoute(const Path& in, double s_in, const Path& out, double s_out, double radius) {
  const PathPose a = in.at(s_in), b = out.at(s_out);
  const Eigen::Vector2d d1(std::cos(a.yaw), std::sin(a.yaw)), d2(std::cos(b.yaw), std::sin(b.yaw));
  const double cross = d1.x() * d2.y() - d1.y() * d2.x();
  if (std::abs(cross) < 1e-3) return Path();  // parallel: no corner
  // Corner K = a.p + u d1 = b.p + v d2.
  const Eigen::Vector2d w = b.p - a.p;
  const double u = (w.x() * d2.y() - w.y() * d2.x()) / cross;
  const double v = (w.x() * d1.y() - w.y() * d1.x()) / cross;
  const double turn = std::remainder(b.yaw - a.yaw, 2 * M_PI);
  const double tangent = radius * std::tan(0.5 * std::abs(turn));
  const double s_entry = s_in + u - tangent, s_exit = s_out + v + tangent;
  if (s_entry <= 0 || s_exit >= out.length()) return Path();
  Path route = in.slice(0, s_entry);
  std::vector<Eigen::Vector2d> arc = arcPoints(in.at(s_entry).p, a.yaw, radius, turn, 0.5);
  route.append(Path(arc));
  route.append(out.slice(s_exit, out.length()));
  return route;
}

}  // namespace sim
}  // namespace ret3d
