#include "ret3d/eval/velocity_error.h"

#include <gtest/gtest.h>

namespace ret3d {
namespace {

Box box(ObjectClass c, double x, double vx, float score = 0.9f) {
  Box b;
  b.x = x, b.y = 0, b.vx = vx, b.label = c, b.score = score, b.length = 4, b.width = 2, b.height = 1.5;
  return b;
}

TEST(VelocityError, MatchesByClassAndDistanceAndSplitsMovingFromStatic) {
  eval::VelocityFrame f;
  f.gt = {box(ObjectClass::Car, 0, 10), box(ObjectClass::Car, 20, 0), box(ObjectClass::Pedestrian, 40, 1.5)};
  f.gt_valid = {true, true, true};
  // The car at 0 is found 1 m off with 8 m/s (error 2); the parked car with 0.3 m/s; the pedestrian only by a
  // cyclist (another class: no match), and a detection 5 m away matches nothing.
  f.pred = {box(ObjectClass::Car, 1, 8), box(ObjectClass::Car, 20.5, 0.3), box(ObjectClass::Cyclist, 40, 1.5),
            box(ObjectClass::Pedestrian, 45, 1.5)};
  const auto s = eval::velocityErrors({f});
  const auto& car = s.at(ObjectClass::Car);
  EXPECT_EQ(car.moving_gt, 1u);
  EXPECT_EQ(car.moving_matched, 1u);
  EXPECT_NEAR(car.moving_median, 2.0, 1e-9);
  EXPECT_EQ(car.static_matched, 1u);
  EXPECT_NEAR(car.static_median, 0.3, 1e-9);
  const auto& ped = s.at(ObjectClass::Pedestrian);
  EXPECT_EQ(ped.moving_gt, 1u);
  EXPECT_EQ(ped.moving_matched, 0u);
}

TEST(VelocityError, TheHigherScoreWinsAndUnknownVelocitiesAreSkipped) {
  eval::VelocityFrame f;
  f.gt = {box(ObjectClass::Car, 0, 10), box(ObjectClass::Car, 30, 10)};
  f.gt_valid = {true, false};
  f.pred = {box(ObjectClass::Car, 0.2, 0, 0.3f), box(ObjectClass::Car, 0.4, 9, 0.8f), box(ObjectClass::Car, 30, 10)};
  const auto stats = eval::velocityErrors({f});  // held: a reference into the temporary map dangled (ASan)
  const auto& car = stats.at(ObjectClass::Car);
  EXPECT_EQ(car.moving_gt, 1u);
  EXPECT_EQ(car.moving_matched, 1u);
  EXPECT_NEAR(car.moving_median, 1.0, 1e-9);
}

}  // namespace
}  // namespace ret3d
