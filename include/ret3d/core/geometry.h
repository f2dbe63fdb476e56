// Box geometry: corners, exact rotated BEV and 3D IoU, point-in-box tests, angle wrapping.
#pragma once

#include <array>
#include <vector>

#include <Eigen/Core>

#include "ret3d/core/types.h"

namespace ret3d {

// Wraps an angle to (-pi, pi].
double wrapAngle(double a);

// The four BEV corners (x, y), counter-clockwise, starting front-left.
std::array<Eigen::Vector2d, 4> bevCorners(const Box& b);
// The eight 3D corners: the bottom four (counter-clockwise from front-left), then the top four above them.
std::array<Eigen::Vector3d, 8> boxCorners(const Box& b);

// Signed area of a simple polygon (positive when counter-clockwise).
double polygonArea(const std::vector<Eigen::Vector2d>& poly);
// Intersection polygon of two convex polygons given counter-clockwise (Sutherland-Hodgman); empty if disjoint.
std::vector<Eigen::Vector2d> convexIntersection(const std::vector<Eigen::Vector2d>& a,
                                                const std::vector<Eigen::Vector2d>& b);

// Exact area of the intersection of two rotated rectangles in BEV.
double bevIntersectionArea(const Box& a, const Box& b);
// Rotated BEV IoU in [0, 1].
double bevIoU(const Box& a, const Box& b);
// 3D IoU: BEV intersection area times height overlap, over the union of volumes.
double iou3d(const Box& a, const Box& b);

// Axis-aligned 2D IoU of image boxes given as (x1, y1, x2, y2).
double iou2d(const std::array<double, 4>& a, const std::array<double, 4>& b);

// True when p lies inside the box (boundaries included).
bool pointInBox(const Box& b, const Eigen::Vector3d& p);
// Number of cloud points inside the box.
std::uint32_t countPointsInBox(const Box& b, const PointCloud& cloud);
// Points inside each box, in one pass over the cloud (a coarse grid over the boxes keeps it fast).
std::vector<std::uint32_t> countPointsInBoxes(const std::vector<Box>& boxes, const PointCloud& cloud);

// A BEV wedge: the region between two rays from one apex (less than 180 degrees apart), grown by a margin; e.g. the
// part of the ground a camera sees, or what lies behind an image region.
struct BevWedge {
  Eigen::Vector2d apex = Eigen::Vector2d::Zero();
  Eigen::Vector2d ray_a = Eigen::Vector2d::UnitX(), ray_b = Eigen::Vector2d::UnitY();  // directions of the edges
  double margin = 0;  // points at most this far outside still count as inside (m)
  // Inside the wedge, or within margin of it.
  bool contains(const Eigen::Vector2d& p) const;
};

}  // namespace ret3d
