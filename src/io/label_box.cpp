// KITTI camera labels (bottom centre and rotation_y in the rectified camera frame) <-> LiDAR-frame boxes
// (geometric centre and yaw about z), exact inverses of each other.
#include <algorithm>
#include <cmath>

#include "ret3d/core/geometry.h"
#include "ret3d/io/kitti.h"

namespace ret3d {
namespace kitti {
namespace {

// The KITTI devkit draws a box only when all corners are at least this far in front of the camera; beyond that, we
// clip the box's edges against this plane so partly visible boxes still get their visible extent.
constexpr double kNearPlane = 0.1;

// The 12 edges of a box, as indices into boxCorners(): bottom ring, top ring, verticals.
constexpr int kEdges[12][2] = {{0, 1}, {1, 2}, {2, 3}, {3, 0}, {4, 5}, {5, 6},
                               {6, 7}, {7, 4}, {0, 4}, {1, 5}, {2, 6}, {3, 7}};

std::array<double, 4> imageBox(const Box& box, const Calibration& calib,
                               const std::optional<Eigen::Vector2d>& image_size) {
  const Eigen::Matrix4d A = calib.veloToRectMatrix();
  std::array<Eigen::Vector3d, 8> rect;
  const auto corners = boxCorners(box);
  for (int i = 0; i < 8; ++i) rect[i] = (A * corners[i].homogeneous()).head<3>();

  double x1 = INFINITY, y1 = INFINITY, x2 = -INFINITY, y2 = -INFINITY;
  const auto add = [&](const Eigen::Vector3d& p) {
    const auto uv = calib.projectRect(p);
    if (!uv) return;
    x1 = std::min(x1, uv->x());
    y1 = std::min(y1, uv->y());
    x2 = std::max(x2, uv->x());
    y2 = std::max(y2, uv->y());
  };
  for (const auto& e : kEdges) {
    const Eigen::Vector3d& a = rect[e[0]];
    const Eigen::Vector3d& b = rect[e[1]];
    const bool fa = a.z() >= kNearPlane, fb = b.z() >= kNearPlane;
    if (fa) add(a);
    if (fb) add(b);
    if (fa != fb) add(a + (b - a) * ((kNearPlane - a.z()) / (b.z() - a.z())));  // where the edge meets the plane
  }
  if (!(x1 <= x2)) return {0, 0, 0, 0};  // nothing in front of the camera
  if (image_size) {
    const double w = image_size->x() - 1, h = image_size->y() - 1;
    x1 = std::clamp(x1, 0.0, w);
    x2 = std::clamp(x2, 0.0, w);
    y1 = std::clamp(y1, 0.0, h);
    y2 = std::clamp(y2, 0.0, h);
  }
  return {x1, y1, x2, y2};
}

}  // namespace

Box labelToBox(const Label& label, const Calibration& calib) {
  const Eigen::Matrix4d velo_from_rect = calib.veloToRectMatrix().inverse();
  // Camera y points down: the geometric centre is half a height above the bottom centre.
  const Eigen::Vector3d centre = (velo_from_rect * Eigen::Vector3d(label.x, label.y - 0.5 * label.h, label.z)
                                                       .homogeneous()).head<3>();
  // rotation_y turns the object's length axis (camera x at rotation_y = 0) about camera y: heading (cos, 0, -sin).
  const Eigen::Vector3d heading_rect(std::cos(label.rotation_y), 0.0, -std::sin(label.rotation_y));
  const Eigen::Vector3d heading = velo_from_rect.topLeftCorner<3, 3>() * heading_rect;

  Box b;
  b.x = centre.x();
  b.y = centre.y();
  b.z = centre.z();
  b.length = label.l;
  b.width = label.w;
  b.height = label.h;
  b.yaw = wrapAngle(std::atan2(heading.y(), heading.x()));
  b.label = classFromName(label.type).value_or(ObjectClass::Unknown);
  b.track_id = label.track_id >= 0 ? static_cast<std::uint32_t>(label.track_id) + 1 : 0;
  if (label.score) b.score = static_cast<float>(*label.score);
  return b;
}

Label boxToLabel(const Box& box, const Calibration& calib, const std::optional<Eigen::Vector2d>& image_size) {
  const Eigen::Matrix4d rect_from_velo = calib.veloToRectMatrix();
  const Eigen::Vector3d centre = (rect_from_velo * box.center().homogeneous()).head<3>();

  // Exact inverse of labelToBox's yaw: the camera heading (cos ry, 0, -sin ry) must map into the vertical LiDAR plane
  // of the box heading, i.e. be orthogonal (after mapping) to the box's lateral direction n. With M the
  // rect -> LiDAR rotation, n . (M d) = (M^T n) . d = 0 gives tan(ry) = m_x / m_z for m = M^T n.
  const Eigen::Matrix3d velo_from_rect = rect_from_velo.topLeftCorner<3, 3>().inverse();
  const Eigen::Vector3d lateral(-std::sin(box.yaw), std::cos(box.yaw), 0.0);
  const Eigen::Vector3d m = velo_from_rect.transpose() * lateral;
  double ry = std::atan2(m.x(), m.z());
  const Eigen::Vector3d back = velo_from_rect * Eigen::Vector3d(std::cos(ry), 0.0, -std::sin(ry));
  if (back.x() * std::cos(box.yaw) + back.y() * std::sin(box.yaw) < 0.0) ry += M_PI;  // the other root faces back

  Label l;
  l.type = box.label == ObjectClass::Unknown ? "Misc" : className(box.label);
  l.track_id = box.track_id > 0 ? static_cast<int>(box.track_id) - 1 : -1;
  l.h = box.height;
  l.w = box.width;
  l.l = box.length;
  l.x = centre.x();
  l.y = centre.y() + 0.5 * box.height;
  l.z = centre.z();
  l.rotation_y = wrapAngle(ry);
  // KITTI's observation angle: rotation_y minus the ray angle to the object, atan2(x, z). This formula reproduces the
  // alpha of the real KITTI labels (median difference 0.004 rad, from their 2-decimal rounding).
  l.alpha = wrapAngle(l.rotation_y - std::atan2(l.x, l.z));
  l.bbox = imageBox(box, calib, image_size);
  l.score = static_cast<double>(box.score);
  return l;
}

}  // namespace kitti
}  // namespace ret3d
