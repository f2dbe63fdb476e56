#include "ret3d/detector/nms.h"

#include <cmath>

#include <gtest/gtest.h>

namespace ret3d {
namespace {

Box box(double x, double y, double yaw, float score, ObjectClass c = ObjectClass::Car, double l = 4, double w = 2) {
  Box b;
  b.x = x, b.y = y, b.yaw = yaw, b.length = l, b.width = w, b.height = 1.5, b.score = score, b.label = c;
  return b;
}

TEST(RotatedNms, KeepsTheBestOfOverlappingBoxes) {
  const std::vector<Box> boxes = {box(0, 0, 0, 0.6f), box(0.3, 0.1, 0.05, 0.9f), box(10, 0, 0, 0.5f)};
  const auto keep = rotatedNms(boxes, 0.1);
  ASSERT_EQ(keep.size(), 2u);
  EXPECT_EQ(keep[0], 1u);  // highest score first
  EXPECT_EQ(keep[1], 2u);  // the far box survives
}

TEST(RotatedNms, PerClassKeepsOverlappingBoxesOfOtherClasses) {
  const std::vector<Box> boxes = {box(0, 0, 0, 0.9f, ObjectClass::Car), box(0, 0, 0, 0.8f, ObjectClass::Cyclist, 1.8, 0.6)};
  EXPECT_EQ(rotatedNms(boxes, 0.1, true).size(), 2u);
  EXPECT_EQ(rotatedNms(boxes, 0.1, false).size(), 1u);
}

TEST(RotatedNms, UsesTheRotatedOverlap) {
  // Same centre, one turned 90 degrees: BEV intersection 2 x 2 = 4, union 8 + 8 - 4 = 12, IoU 1/3.
  const std::vector<Box> boxes = {box(0, 0, 0, 0.9f), box(0, 0, M_PI / 2, 0.8f)};
  EXPECT_EQ(rotatedNms(boxes, 0.3).size(), 1u);   // 1/3 > 0.3: suppressed
  EXPECT_EQ(rotatedNms(boxes, 0.34).size(), 2u);  // 1/3 < 0.34: kept
  // Axis-aligned boxes that touch only at the corners of their rotated versions are kept.
  const std::vector<Box> side = {box(0, 0, 0, 0.9f), box(0, 2.0, 0, 0.8f)};  // edge contact, IoU 0
  EXPECT_EQ(rotatedNms(side, 0.0).size(), 2u);
}

TEST(RotatedNms, MaxKeepAndEmptyInput) {
  EXPECT_TRUE(rotatedNms({}, 0.1).empty());
  const std::vector<Box> boxes = {box(0, 0, 0, 0.1f), box(10, 0, 0, 0.3f), box(20, 0, 0, 0.2f)};
  const auto keep = rotatedNms(boxes, 0.1, true, 2);
  ASSERT_EQ(keep.size(), 2u);
  EXPECT_EQ(keep[0], 1u);
  EXPECT_EQ(keep[1], 2u);
}

}  // namespace
}  // namespace ret3d
