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

TEST(VoteBoxes, KeptBoxesBecomeTheScoreWeightedMeanOfTheirOverlappingCandidates) {
  std::vector<Box> boxes = {box(0, 0, 0, 0.75f), box(0.4, 0.2, 0.1, 0.25f), box(10, 0, 0, 0.5f),
                            box(0, 0, 0, 0.9f, ObjectClass::Cyclist, 1.8, 0.6)};
  boxes[1].length = 4.0 * std::exp(0.4);  // log sizes are averaged
  boxes[1].vx = 4.0;
  const auto keep = rotatedNms(boxes, 0.1);
  ASSERT_EQ(keep.size(), 3u);
  const auto voted = voteBoxes(boxes, keep, 0.3);
  ASSERT_EQ(voted.size(), 3u);
  // keep: cyclist (0.9), car 0 (0.75), far car (0.5).
  const Box& car = voted[1];
  EXPECT_NEAR(car.x, 0.25 * 0.4, 1e-9);
  EXPECT_NEAR(car.y, 0.25 * 0.2, 1e-9);
  EXPECT_NEAR(car.yaw, 0.25 * 0.1, 1e-9);
  EXPECT_NEAR(car.length, 4.0 * std::exp(0.25 * 0.4), 1e-9);
  EXPECT_NEAR(car.vx, 1.0, 1e-9);
  EXPECT_FLOAT_EQ(car.score, 0.75f);  // the score stays the kept box's
  EXPECT_EQ(voted[0].x, 0.0);         // the cyclist overlaps the car but is of another class: untouched
  EXPECT_EQ(voted[0].length, 1.8);
  EXPECT_EQ(voted[2].x, 10.0);        // nothing overlaps the far car
  // Below the voting IoU a candidate has no say.
  EXPECT_EQ(voteBoxes(boxes, keep, 0.95)[1].x, 0.0);
}

TEST(VoteBoxes, AFlippedCandidateVotesForTheSameAxis) {
  const std::vector<Box> boxes = {box(0, 0, 0.1, 0.5f), box(0, 0, 0.1 + M_PI, 0.5f)};
  const auto voted = voteBoxes(boxes, {0}, 0.5);
  ASSERT_EQ(voted.size(), 1u);
  EXPECT_NEAR(voted[0].yaw, 0.1, 1e-9);  // not 0.1 + pi / 2
}

}  // namespace
}  // namespace ret3d
