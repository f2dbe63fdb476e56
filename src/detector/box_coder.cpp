#include "ret3d/detector/box_coder.h"

#include <algorithm>
#include <cmath>

#include "ret3d/core/geometry.h"

namespace ret3d {

namespace {
// Log-size decoding is clamped so an untrained head cannot produce infinite boxes.
double expClamped(double x) { return std::exp(std::min(6.0, std::max(-6.0, x))); }
}  // namespace

BoxCode encodeAnchorBox(const Box& b, const Anchor& a, int u, int v, int stride, const BevGeometry& g, double dt) {
  const Eigen::Vector2d f = g.metricToFeature(b.x, b.y, stride);
  return {static_cast<float>(f.x() - u), static_cast<float>(f.y() - v),
          static_cast<float>((b.z - a.z) / a.height), static_cast<float>(std::log(b.length / a.length)),
          static_cast<float>(std::log(b.width / a.width)), static_cast<float>(std::log(b.height / a.height)),
          static_cast<float>(std::sin(b.yaw)), static_cast<float>(std::cos(b.yaw)),
          static_cast<float>(b.vx * dt), static_cast<float>(b.vy * dt)};
}

Box decodeAnchorBox(const BoxCode& c, const Anchor& a, int u, int v, int stride, const BevGeometry& g, double dt) {
  Box b;
  const Eigen::Vector2d m = g.featureToMetric(u + c[0], v + c[1], stride);
  b.x = m.x();
  b.y = m.y();
  b.z = a.z + c[2] * a.height;
  b.length = a.length * expClamped(c[3]);
  b.width = a.width * expClamped(c[4]);
  b.height = a.height * expClamped(c[5]);
  b.yaw = wrapAngle(std::atan2(c[6], c[7]));
  b.vx = c[8] / dt;
  b.vy = c[9] / dt;
  b.label = a.label;
  return b;
}

BoxCode encodeCenterBox(const Box& b, int u, int v, int stride, const BevGeometry& g, double dt) {
  const Eigen::Vector2d f = g.metricToFeature(b.x, b.y, stride);
  return {static_cast<float>(f.x() - u), static_cast<float>(f.y() - v), static_cast<float>(b.z),
          static_cast<float>(std::log(b.length)), static_cast<float>(std::log(b.width)),
          static_cast<float>(std::log(b.height)), static_cast<float>(std::sin(b.yaw)),
          static_cast<float>(std::cos(b.yaw)), static_cast<float>(b.vx * dt), static_cast<float>(b.vy * dt)};
}

Box decodeCenterBox(const BoxCode& c, int u, int v, int stride, const BevGeometry& g, double dt) {
  Box b;
  const Eigen::Vector2d m = g.featureToMetric(u + c[0], v + c[1], stride);
  b.x = m.x();
  b.y = m.y();
  b.z = c[2];
  b.length = expClamped(c[3]);
  b.width = expClamped(c[4]);
  b.height = expClamped(c[5]);
  b.yaw = wrapAngle(std::atan2(c[6], c[7]));
  b.vx = c[8] / dt;
  b.vy = c[9] / dt;
  return b;
}

}  // namespace ret3d
