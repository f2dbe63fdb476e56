#include "ret3d/detector/anchors.h"

#include <random>

#include <gtest/gtest.h>

namespace ret3d {
namespace {

Box sized(ObjectClass c, double l, double w, double h, double z) {
  Box b;
  b.label = c;
  b.length = l, b.width = w, b.height = h, b.z = z;
  return b;
}

TEST(KMeansAnchors, RecoversTwoClustersPerClassWithZAndHeight) {
  std::mt19937 rng(3);
  std::normal_distribution<double> n(0.0, 0.03);
  std::vector<Box> boxes;
  // Cars: small cars around 3.6 x 1.6 x 1.5 at z -1.0 and vans-like 5.0 x 2.0 x 2.2 at z -0.6.
  for (int i = 0; i < 60; ++i) boxes.push_back(sized(ObjectClass::Car, 3.6 + n(rng), 1.6 + n(rng), 1.5 + n(rng), -1.0 + n(rng)));
  for (int i = 0; i < 40; ++i) boxes.push_back(sized(ObjectClass::Car, 5.0 + n(rng), 2.0 + n(rng), 2.2 + n(rng), -0.6 + n(rng)));
  for (int i = 0; i < 30; ++i)
    boxes.push_back(sized(ObjectClass::Pedestrian, 0.8 + n(rng), 0.6 + n(rng), 1.75 + n(rng), -0.9 + n(rng)));
  const auto anchors = kmeansAnchors(boxes, {ObjectClass::Car, ObjectClass::Pedestrian}, 2, 7);
  ASSERT_EQ(anchors.size(), 4u);  // k per class (the pedestrians' one tight cluster is split in two)
  EXPECT_EQ(anchors[0].label, ObjectClass::Car);
  EXPECT_NEAR(anchors[0].length, 3.6, 0.05);
  EXPECT_NEAR(anchors[0].height, 1.5, 0.05);
  EXPECT_NEAR(anchors[0].z, -1.0, 0.05);
  EXPECT_EQ(anchors[1].label, ObjectClass::Car);
  EXPECT_NEAR(anchors[1].length, 5.0, 0.05);
  EXPECT_NEAR(anchors[1].width, 2.0, 0.05);
  EXPECT_NEAR(anchors[1].height, 2.2, 0.05);
  EXPECT_NEAR(anchors[1].z, -0.6, 0.05);
  EXPECT_EQ(anchors[2].label, ObjectClass::Pedestrian);
  EXPECT_EQ(anchors[3].label, ObjectClass::Pedestrian);
  EXPECT_NEAR(anchors[2].height, 1.75, 0.05);
  EXPECT_LE(anchors[2].length * anchors[2].width, anchors[3].length * anchors[3].width);  // sorted by area
  // Deterministic for a seed.
  const auto again = kmeansAnchors(boxes, {ObjectClass::Car, ObjectClass::Pedestrian}, 2, 7);
  for (std::size_t i = 0; i < anchors.size(); ++i) EXPECT_DOUBLE_EQ(anchors[i].length, again[i].length);
}

TEST(KMeansAnchors, FewBoxesAndMissingClasses) {
  std::vector<Box> boxes = {sized(ObjectClass::Cyclist, 1.8, 0.6, 1.7, -0.8)};
  const auto anchors = kmeansAnchors(boxes, {ObjectClass::Car, ObjectClass::Cyclist}, 3, 1);
  ASSERT_EQ(anchors.size(), 2u);  // Car: none -> one typical anchor; Cyclist: one distinct box -> one anchor
  EXPECT_EQ(anchors[0].label, ObjectClass::Car);
  EXPECT_NEAR(anchors[0].length, 3.9, 1e-9);
  EXPECT_EQ(anchors[1].label, ObjectClass::Cyclist);
  EXPECT_DOUBLE_EQ(anchors[1].length, 1.8);
  EXPECT_DOUBLE_EQ(anchors[1].z, -0.8);
}

TEST(KMeansAnchors, ShapeIoUIncludesZ) {
  const Anchor a{ObjectClass::Car, 4, 2, 2, 0, 0};
  EXPECT_DOUBLE_EQ(anchorShapeIoU(a, 4, 2, 2, 0), 1.0);
  EXPECT_NEAR(anchorShapeIoU(a, 4, 2, 2, 1.0), 8.0 / 24.0, 1e-12);  // half the height overlaps
  EXPECT_DOUBLE_EQ(anchorShapeIoU(a, 4, 2, 2, 2.5), 0.0);
  EXPECT_NEAR(anchorShapeIoU(a, 2, 1, 2, 0), 4.0 / 16.0, 1e-12);
}

TEST(KMeansAnchors, StridesFollowTheSize) {
  auto anchors = defaultAnchors({ObjectClass::Car, ObjectClass::Pedestrian, ObjectClass::Cyclist}, 1);
  assignAnchorStrides(&anchors, {8, 4}, 0.25, 0.6);
  EXPECT_EQ(anchors[0].stride, 8);  // car: 2 m cells <= 0.6 * 3.9
  EXPECT_EQ(anchors[1].stride, 4);  // pedestrian: finest
  EXPECT_EQ(anchors[2].stride, 4);  // cyclist: 1 m <= 0.6 * 1.76, 2 m is not
}

}  // namespace
}  // namespace ret3d
