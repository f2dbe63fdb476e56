#include "ret3d/relation/intra_rm_targets.h"

#include <cmath>

#include <gtest/gtest.h>

namespace ret3d {
namespace relation {
namespace {

Box car(double x, double y, double yaw = 0) {
  Box b;
  b.x = x, b.y = y, b.z = -0.8, b.length = 4, b.width = 1.8, b.height = 1.5, b.yaw = yaw;
  b.label = ObjectClass::Car;
  return b;
}

TEST(IntraRMTargets, ClassAwareBevIoUAssignment) {
  FrameGroundTruth gt;
  gt.boxes = {car(10, 0), car(20, 5)};
  Box ped = car(30, 0);
  ped.label = ObjectClass::Pedestrian, ped.length = 0.8, ped.width = 0.6;
  gt.boxes.push_back(ped);
  Box exact = car(10, 0), shifted = car(20.8, 5, M_PI + 0.1), fp = car(40, 0);
  Box wrong_class = ped;
  wrong_class.label = ObjectClass::Cyclist;  // on a pedestrian, but class-aware: no match
  const auto t = assignIntraRMTargets({exact, shifted, fp, wrong_class}, gt, IntraRMTrainConfig{});
  ASSERT_EQ(t.size(), 4u);
  EXPECT_FLOAT_EQ(t[0].cls[0], 1);
  EXPECT_TRUE(t[0].regress);
  EXPECT_NEAR(t[0].dx, 0, 1e-6);
  // 0.8 m along a 4 m car at BEV IoU ~0.65: below the 0.7 positive threshold, still regressed; the heading residual is
  // taken modulo pi (the box faces backwards: only the 0.1 rad axis error counts).
  EXPECT_FLOAT_EQ(t[1].cls[0], 0);
  EXPECT_TRUE(t[1].regress);
  EXPECT_NEAR(t[1].dx, -0.8, 1e-6);
  EXPECT_NEAR(t[1].dyaw, -0.1, 1e-6);
  EXPECT_FALSE(t[2].regress);
  EXPECT_FLOAT_EQ(t[2].cls[0] + t[2].cls[1] + t[2].cls[2], 0);
  EXPECT_FLOAT_EQ(t[2].cls_weight, 1);
  EXPECT_FALSE(t[3].regress);
  EXPECT_FLOAT_EQ(t[3].cls[2], 0);
  EXPECT_FLOAT_EQ(t[3].cls[1], 1) << "the pedestrian channel still sees the pedestrian under it";
}

TEST(IntraRMTargets, VanAndDontCareAreIgnoredNotPenalised) {
  FrameGroundTruth gt;
  gt.similar = {car(10, 0)};  // a Van, labelled with the class it is confused with
  const auto t = assignIntraRMTargets({car(10.2, 0), car(30, 0), car(50, 0)}, gt, IntraRMTrainConfig{},
                                      {false, true, false});
  EXPECT_FLOAT_EQ(t[0].cls_weight, 0);
  EXPECT_FLOAT_EQ(t[1].cls_weight, 0);
  EXPECT_FLOAT_EQ(t[2].cls_weight, 1);
}

TEST(IntraRMTargets, SizeResidualsAreLogRatios) {
  FrameGroundTruth gt;
  gt.boxes = {car(0, 0)};
  Box d = car(0, 0);
  d.length = 3.6;
  const auto t = assignIntraRMTargets({d}, gt, IntraRMTrainConfig{});
  EXPECT_NEAR(t[0].dl, std::log(4.0 / 3.6), 1e-6);
  EXPECT_NEAR(t[0].dw, 0, 1e-6);
}

TEST(IntraRMTargets, AQuarterTurnIsTakenAsSwappedLengthAndWidth) {
  FrameGroundTruth gt;
  Box g = car(0, 0, M_PI / 2 + 0.05);
  g.label = ObjectClass::Pedestrian, g.length = 0.8, g.width = 0.6;
  gt.boxes = {g};
  Box d = g;
  d.yaw = 0, d.length = 0.6, d.width = 0.8;  // the same rectangle, described a quarter turn away
  const auto t = assignIntraRMTargets({d}, gt, IntraRMTrainConfig{});
  ASSERT_TRUE(t[0].regress);
  EXPECT_NEAR(t[0].dyaw, 0.05, 1e-6);
  EXPECT_NEAR(t[0].dl, 0, 1e-6);
  EXPECT_NEAR(t[0].dw, 0, 1e-6);
}

}  // namespace
}  // namespace relation
}  // namespace ret3d
