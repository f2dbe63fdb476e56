// Polylines with arc length: road centre lines, lanes, sidewalk walkways and the routes actors follow.
#pragma once

#include <vector>

#include <Eigen/Core>

namespace ret3d {
namespace sim {

struct PathPose {
  Eigen::Vector2d p;
  double yaw = 0;
};

class Path {
 public:
  Path() = default;
  explicit Path(std::vector<Eigen::Vector2d> points);  // consecutive duplicates are dropped

  bool empty() const { return pts_.size() < 2; }
  double length() const { return s_.empty() ? 0.0 : s_.back(); }
  const std::vector<Eigen::Vector2d>& points() const { return pts_; }
  const std::vector<double>& stations() const { return s_; }

  // Position and heading at arc length s (clamped to the ends).
  PathPose at(double s) const;
  // The path offset sideways by `d` (left positive), resampled at the same stations.
  Path offset(double d) const;
  // The same points in reverse order.
  Path reversed() const;
  // The part between stations s0 < s1, resampled every `step` metres.
  Path slice(double s0, double s1, double step = 1.0) const;
  // Station of the point closest to q, and its signed lateral distance (left positive).
  double project(const Eigen::Vector2d& q, double* lateral = nullptr) const;
  // Appends another path (its first point joins this path's last).
  void append(const Path& other);

 private:
  void rebuild();
  std::vector<Eigen::Vector2d> pts_;
  std::vector<double> s_;
};

// Points along a circular arc of `radius` from heading yaw0 turning by `angle` (left positive) starting at p0,
// every `step` metres (p0 excluded).
std::vector<Eigen::Vector2d> arcPoints(const Eigen::Vector2d& p0, double yaw0, double radius, double angle,
                                       double step);

// A route that follows `in` up to a corner, turns through a circular fillet of `radius` and continues on `out`.
// The corner is where the two paths' lines meet near station s_in of `in` and s_out of `out` (both straight there).
Path filletRoute(const Path& in, double s_in, const Path& out, double s_out, double radius);

}  // namespace sim
}  // namespace ret3d
