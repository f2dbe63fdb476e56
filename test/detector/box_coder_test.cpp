#include "ret3d/detector/box_coder.h"

#include <cmath>

#include <gtest/gtest.h>

#include "support/boxes.h"

namespace ret3d {
namespace {

void expectSameBox(const Box& a, const Box& b) {
  test::expectSameCentreAndSize(a, b, 1e-4);
  EXPECT_NEAR(std::remainder(a.yaw - b.yaw, 2 * M_PI), 0.0, 1e-5);
  EXPECT_NEAR(a.vx, b.vx, 1e-4);
  EXPECT_NEAR(a.vy, b.vy, 1e-4);
}

Box sampleBox() {
  Box b;
  b.x = 12.34, b.y = -7.81, b.z = -0.9;
  b.length = 4.2, b.width = 1.8, b.height = 1.6;
  b.yaw = -2.7;
  b.vx = 8.5, b.vy = -1.25;
  b.label = ObjectClass::Car;
  return b;
}

TEST(BoxCoder, AnchorEncodeThenDecodeReturnsTheBoxFromItsCellAndNeighbours) {
  BevGeometry g;
  const Anchor a{ObjectClass::Car, 3.9, 1.6, 1.56, -1.0, 8};
  const Box b = sampleBox();
  const Eigen::Vector2d f = g.metricToFeature(b.x, b.y, 8);
  const int u = static_cast<int>(std::floor(f.x())), v = static_cast<int>(std::floor(f.y()));
  // The cell itself and the two nearest neighbours (the ones the head also trains).
  const int nu = f.x() - u < 0.5 ? -1 : 1, nv = f.y() - v < 0.5 ? -1 : 1;
  for (const auto& [du, dv] : std::vector<std::pair<int, int>>{{0, 0}, {nu, 0}, {0, nv}}) {
    const BoxCode c = encodeAnchorBox(b, a, u + du, v + dv, 8, g, 0.1);
    EXPECT_GT(c[0], -0.5f);  // within the (2 sigmoid - 0.5) range of the head
    EXPECT_LT(c[0], 1.5f);
    const Box d = decodeAnchorBox(c, a, u + du, v + dv, 8, g, 0.1);
    expectSameBox(d, b);
    EXPECT_EQ(d.label, ObjectClass::Car);
  }
  // The code itself: size relative to the anchor, heading as (sin, cos), velocity as metres per sweep.
  const BoxCode c = encodeAnchorBox(b, a, u, v, 8, g, 0.1);
  EXPECT_NEAR(c[3], std::log(4.2 / 3.9), 1e-6);
  EXPECT_NEAR(c[2], (-0.9 + 1.0) / 1.56, 1e-6);
  EXPECT_NEAR(c[6], std::sin(-2.7), 1e-6);
  EXPECT_NEAR(c[7], std::cos(-2.7), 1e-6);
  EXPECT_NEAR(c[8], 0.85, 1e-6);
}

TEST(BoxCoder, CenterEncodeThenDecodeReturnsTheBox) {
  BevGeometry g;
  g.resolution = 0.2;
  const Box b = sampleBox();
  const Eigen::Vector2d f = g.metricToFeature(b.x, b.y, 4);
  const int u = static_cast<int>(std::floor(f.x())), v = static_cast<int>(std::floor(f.y()));
  const BoxCode c = encodeCenterBox(b, u, v, 4, g, 0.1);
  EXPECT_GE(c[0], 0.0f);
  EXPECT_LT(c[0], 1.0f);
  expectSameBox(decodeCenterBox(c, u, v, 4, g, 0.1), b);
  // Heading survives the (sin, cos) round trip at pi.
  Box flipped = b;
  flipped.yaw = M_PI;
  EXPECT_NEAR(std::abs(decodeCenterBox(encodeCenterBox(flipped, u, v, 4, g, 0.1), u, v, 4, g, 0.1).yaw), M_PI, 1e-6);
}

}  // namespace
}  // namespace ret3d
