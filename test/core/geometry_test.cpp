#include "ret3d/core/geometry.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>

#include "ret3d/core/transform.h"
#include "support/boxes.h"

namespace ret3d {
namespace {

using test::makeBox;

TEST(WrapAngle, MapsIntoHalfOpenInterval) {
  EXPECT_NEAR(wrapAngle(0.0), 0.0, 1e-12);
  EXPECT_NEAR(wrapAngle(M_PI), M_PI, 1e-12);
  EXPECT_NEAR(wrapAngle(-M_PI), M_PI, 1e-12);  // -pi is not in (-pi, pi]
  EXPECT_NEAR(wrapAngle(3 * M_PI), M_PI, 1e-9);
  EXPECT_NEAR(wrapAngle(2 * M_PI + 0.5), 0.5, 1e-12);
  EXPECT_NEAR(wrapAngle(-2 * M_PI - 0.5), -0.5, 1e-12);
  EXPECT_NEAR(wrapAngle(1.5 * M_PI), -0.5 * M_PI, 1e-12);
}

TEST(Corners, AxisAlignedAndRotated) {
  const auto c = bevCorners(makeBox(1, 2, 0, 4, 2, 1, 0));
  EXPECT_NEAR(c[0].x(), 3, 1e-12);
  EXPECT_NEAR(c[0].y(), 3, 1e-12);
  EXPECT_NEAR(c[2].x(), -1, 1e-12);
  EXPECT_NEAR(c[2].y(), 1, 1e-12);
  EXPECT_GT(polygonArea({c.begin(), c.end()}), 0.0);  // counter-clockwise
  const auto r = bevCorners(makeBox(0, 0, 0, 4, 2, 1, M_PI / 2));
  EXPECT_NEAR(r[0].x(), -1, 1e-12);  // front-left (+2, +1) rotated by 90 degrees
  EXPECT_NEAR(r[0].y(), 2, 1e-12);
  const auto c3 = boxCorners(makeBox(0, 0, 1, 2, 2, 2, 0.3));
  EXPECT_NEAR(c3[0].z(), 0, 1e-12);
  EXPECT_NEAR(c3[4].z(), 2, 1e-12);
}

TEST(BevIoU, HandComputedCases) {
  const Box a = makeBox(0, 0, 0, 2, 2, 1, 0);
  EXPECT_NEAR(bevIoU(a, a), 1.0, 1e-12);
  EXPECT_NEAR(iou3d(a, a), 1.0, 1e-12);
  EXPECT_EQ(bevIoU(a, makeBox(10, 0, 0, 2, 2, 1, 0)), 0.0);
  // Two 2x2 squares offset by 1 m in x: intersection 2, union 6.
  EXPECT_NEAR(bevIoU(a, makeBox(1, 0, 0, 2, 2, 1, 0)), 1.0 / 3.0, 1e-12);
  // A 2x2 square against itself rotated 45 degrees: a regular octagon of area 8(sqrt(2) - 1).
  const Box r = makeBox(0, 0, 0, 2, 2, 1, M_PI / 4);
  const double inter = 8.0 * (std::sqrt(2.0) - 1.0);
  EXPECT_NEAR(bevIntersectionArea(a, r), inter, 1e-12);
  EXPECT_NEAR(bevIoU(a, r), inter / (8.0 - inter), 1e-12);
  EXPECT_NEAR(bevIoU(a, r), 0.7071, 1e-4);
}

TEST(BevIoU, TouchingAndParallelEdges) {
  const Box a = makeBox(0, 0, 0, 2, 2, 1, 0);
  EXPECT_NEAR(bevIoU(a, makeBox(2, 0, 0, 2, 2, 1, 0)), 0.0, 1e-12);    // shared edge
  EXPECT_NEAR(bevIoU(a, makeBox(2, 2, 0, 2, 2, 1, 0)), 0.0, 1e-12);    // shared corner
  EXPECT_NEAR(bevIoU(a, makeBox(0, 0, 0, 2, 1, 1, 0)), 0.5, 1e-12);    // contained, collinear edges
  EXPECT_NEAR(bevIoU(a, makeBox(0, 0.5, 0, 2, 2, 1, M_PI)), 3.0 / 5.0, 1e-12);  // 2 x 1.5 over 4 + 4 - 3
  // A box and the same box with yaw + pi (same footprint).
  const Box b = makeBox(3, -1, 0, 4, 1.8, 1.5, 0.4);
  Box b2 = b;
  b2.yaw = b.yaw + M_PI;
  EXPECT_NEAR(bevIoU(b, b2), 1.0, 1e-12);
}

TEST(BevIoU, YawPlusTwoPiAndPlusMinusPi) {
  const Box a = makeBox(0.3, 0.2, 0, 4, 1.7, 1.5, 0.7);
  const Box b = makeBox(1.0, 0.5, 0.2, 3.8, 1.6, 1.4, -0.2);
  Box b2 = b;
  b2.yaw += 2 * M_PI;
  EXPECT_NEAR(bevIoU(a, b), bevIoU(a, b2), 1e-12);
  EXPECT_NEAR(iou3d(a, b), iou3d(a, b2), 1e-12);
  Box p = makeBox(0, 0, 0, 4, 2, 1, M_PI), m = makeBox(0, 0, 0, 4, 2, 1, -M_PI);
  EXPECT_NEAR(bevIoU(p, m), 1.0, 1e-12);
  EXPECT_NEAR(bevIoU(p, makeBox(0, 0, 0, 4, 2, 1, 0)), 1.0, 1e-12);
}

TEST(Iou3d, HalfHeightOverlap) {
  const Box a = makeBox(0, 0, 0, 2, 2, 2, 0);
  const Box b = makeBox(0, 0, 1, 2, 2, 2, 0);  // overlaps the upper half of a
  EXPECT_NEAR(iou3d(a, b), 1.0 / 3.0, 1e-12);
  EXPECT_EQ(iou3d(a, makeBox(0, 0, 2, 2, 2, 2, 0)), 0.0);  // touching faces
}

TEST(BevIoU, SymmetricAndBoundedOnRandomBoxes) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> pos(-2, 2), size(0.3, 5), ang(-M_PI, M_PI);
  for (int i = 0; i < 2000; ++i) {
    const Box a = makeBox(pos(rng), pos(rng), 0, size(rng), size(rng), 1, ang(rng));
    const Box b = makeBox(pos(rng), pos(rng), 0, size(rng), size(rng), 1, ang(rng));
    const double ab = bevIoU(a, b), ba = bevIoU(b, a);
    ASSERT_GE(ab, 0.0);
    ASSERT_LE(ab, 1.0);
    ASSERT_NEAR(ab, ba, 1e-9);
    ASSERT_LE(bevIntersectionArea(a, b), std::min(a.length * a.width, b.length * b.width) + 1e-9);
  }
}

TEST(PointsInBox, CountsInsideOnly) {
  const Box b = makeBox(5, 0, 1, 4, 2, 2, M_PI / 2);  // length along y after rotation
  PointCloud cloud;
  cloud.points = {{5, 1.9f, 1, 0}, {5, -1.9f, 0.1f, 0}, {5.9f, 0, 1.9f, 0}, {6.2f, 0, 1, 0}, {5, 0, 2.2f, 0},
                  {5, 2.1f, 1, 0}};
  EXPECT_EQ(countPointsInBox(b, cloud), 3u);
  const auto counts = countPointsInBoxes({b, makeBox(-20, 0, 0, 1, 1, 1, 0)}, cloud);
  EXPECT_EQ(counts[0], 3u);
  EXPECT_EQ(counts[1], 0u);
}

TEST(PointsInBox, GridMatchesBruteForce) {
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> pos(-30, 30), size(0.5, 6), ang(-M_PI, M_PI);
  std::vector<Box> boxes;
  for (int i = 0; i < 40; ++i) boxes.push_back(makeBox(pos(rng), pos(rng), 0, size(rng), size(rng), 2, ang(rng)));
  PointCloud cloud;
  std::uniform_real_distribution<float> p(-32, 32), z(-1.2f, 1.2f);
  for (int i = 0; i < 50000; ++i) cloud.points.push_back({p(rng), p(rng), z(rng), 0});
  const auto counts = countPointsInBoxes(boxes, cloud);
  for (std::size_t i = 0; i < boxes.size(); ++i) EXPECT_EQ(counts[i], countPointsInBox(boxes[i], cloud));
}

// Garbage points a driver may send (finite but far beyond float's useful range) are simply outside every box.
TEST(PointsInBox, HugeFiniteCoordinatesAreOutside) {
  const float big = std::numeric_limits<float>::max();
  PointCloud cloud;
  cloud.points = {{big, big, 0, 0}, {-big, 1e30f, 0, 0}, {1e30f, -big, 0, 0}, {-1.5f, -0.5f, 0.5f, 0}};
  const auto counts = countPointsInBoxes({makeBox(-1.5, -0.5, 0.5, 2, 2, 2, 0.3)}, cloud);
  EXPECT_EQ(counts[0], 1u);
}

TEST(Transform, BoxRoundTripAndYaw) {
  const Eigen::Isometry3d T = makeTransform(10, -3, 0.5, 2.5);
  Box b = makeBox(1, 2, 0.3, 4, 1.8, 1.5, 2.0);
  b.vx = 3;
  b.vy = -1;
  const Box t = transformBox(b, T);
  EXPECT_NEAR(t.yaw, wrapAngle(4.5), 1e-12);
  EXPECT_NEAR(std::hypot(t.vx, t.vy), std::hypot(3.0, -1.0), 1e-12);
  const Box back = transformBox(t, T.inverse());
  EXPECT_NEAR(back.x, b.x, 1e-9);
  EXPECT_NEAR(back.y, b.y, 1e-9);
  EXPECT_NEAR(back.z, b.z, 1e-9);
  EXPECT_NEAR(back.yaw, b.yaw, 1e-9);
  EXPECT_NEAR(back.vx, b.vx, 1e-9);
  EXPECT_NEAR(yawOf(T), 2.5, 1e-12);
}

}  // namespace
}  // namespace ret3d
