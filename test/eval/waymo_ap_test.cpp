#include "ret3d/eval/waymo_ap.h"

#include <gtest/gtest.h>

#include <cmath>

#include "ret3d/core/geometry.h"
#include "support/boxes.h"

namespace ret3d {
namespace eval {
namespace {

Box car(double x, double y, std::uint32_t points, float score = 1.0f, double yaw = 0.3) {
  Box b = test::carBox(x, y);
  b.yaw = yaw;
  b.num_points = points;
  b.score = score;
  return b;
}

EvalFrame frameWith(std::vector<Box> gt, std::vector<Box> pred) {
  EvalFrame f;
  f.gt_boxes = std::move(gt);
  f.gt_ignore.assign(f.gt_boxes.size(), 0);
  f.pred_boxes = std::move(pred);
  return f;
}

const WaymoClassResult& carResult(const WaymoResult& r) { return r.classes.at(0); }

TEST(WaymoAp, InterpolatedApIsTheAreaUnderTheMonotoneCurve) {
  // Points (0.5, 1.0), (1.0, 0.5): 0.5 x 1 + 0.5 x 0.5 = 0.75.
  EXPECT_NEAR(interpolatedAp({0.5, 1.0}, {1.0, 0.5}), 75.0, 1e-12);
  // A dip is lifted to the best precision further right: (0.25, 0.5), (0.5, 1.0) -> 0.5 x 1.
  EXPECT_NEAR(interpolatedAp({0.25, 0.5}, {0.5, 1.0}), 50.0, 1e-12);
  EXPECT_NEAR(headingAccuracy(0.1, 0.1), 1.0, 1e-12);
  EXPECT_NEAR(headingAccuracy(M_PI - 0.1, -M_PI + 0.1), 1.0 - 0.2 / M_PI, 1e-12);  // wrapped across +-pi
  EXPECT_NEAR(headingAccuracy(0.3 + M_PI, 0.3), 0.0, 1e-12);
}

TEST(WaymoAp, PerfectPredictionsGive100AndNoneGive0) {
  std::vector<EvalFrame> frames = {frameWith({car(10, 0, 100), car(-20, 5, 50)}, {}),
                                   frameWith({car(35, -3, 20), car(60, 0, 8)}, {})};
  for (auto& f : frames) f.pred_boxes = f.gt_boxes;
  const WaymoResult r = evaluateWaymo(frames);
  for (int l = 0; l < kWaymoNumLevels; ++l) {
    EXPECT_NEAR(carResult(r).levels[l].ap, 100.0, 1e-9);
    EXPECT_NEAR(carResult(r).levels[l].aph, 100.0, 1e-9);
    EXPECT_NEAR(r.mean_ap[l], 100.0, 1e-9);  // only Car has ground truth
  }
  EXPECT_EQ(carResult(r).levels[0].num_gt, 4);
  for (std::size_t k = 0; k < 3; ++k) EXPECT_NEAR(carResult(r).ranges[k][1].ap, 100.0, 1e-9);
  for (auto& f : frames) f.pred_boxes.clear();
  const WaymoResult none = evaluateWaymo(frames);
  EXPECT_DOUBLE_EQ(carResult(none).levels[0].ap, 0.0);
  EXPECT_DOUBLE_EQ(carResult(none).levels[1].aph, 0.0);
}

TEST(WaymoAp, HeadingOffByPiGivesAphZeroWithApUnchanged) {
  std::vector<EvalFrame> frames = {frameWith({car(10, 0, 100), car(-20, 5, 50)}, {})};
  for (const Box& g : frames[0].gt_boxes) frames[0].pred_boxes.push_back(car(g.x, g.y, 0, 0.9f, g.yaw + M_PI));
  const WaymoResult r = evaluateWaymo(frames);
  EXPECT_NEAR(carResult(r).levels[0].ap, 100.0, 1e-9);
  EXPECT_NEAR(carResult(r).levels[0].aph, 0.0, 1e-9);
}

// Ground truth: A with 100 points (LEVEL_1), B with 3 (LEVEL_2), C with none (dropped). Predictions on C (0.95),
// A (0.9), B (0.8).
//   LEVEL_1: C's prediction is a FP (C is not ground truth), B's is ignored; points (r, p): (0, 0), (1, 1/2) -> 50.
//   LEVEL_2: n_gt 2: (0, 0), (1/2, 1/2), (1, 2/3); monotone 2/3 throughout -> 66.67.
//   Without point counts all three are LEVEL_1 ground truth: 100.
TEST(WaymoAp, LevelsFromPointCounts) {
  std::vector<EvalFrame> frames = {frameWith({car(10, 0, 100), car(20, 0, 3), car(30, 0, 0)},
                                             {car(30, 0, 0, 0.95f), car(10, 0, 0, 0.9f), car(20, 0, 0, 0.8f)})};
  const WaymoResult r = evaluateWaymo(frames);
  EXPECT_EQ(carResult(r).levels[0].num_gt, 1);
  EXPECT_EQ(carResult(r).levels[1].num_gt, 2);
  EXPECT_NEAR(carResult(r).levels[0].ap, 50.0, 1e-9);
  EXPECT_NEAR(carResult(r).levels[1].ap, 200.0 / 3.0, 1e-9);
  EXPECT_EQ(r.dropped_empty_gt, 1u);
  WaymoOptions o;
  o.use_point_counts = false;
  const WaymoResult all = evaluateWaymo(frames, o);
  EXPECT_EQ(carResult(all).levels[0].num_gt, 3);
  EXPECT_NEAR(carResult(all).levels[0].ap, 100.0, 1e-9);
}

// Range bins: a hit at 10 m and a miss at 40 m (its prediction 3 m off, a FP in the same bin).
TEST(WaymoAp, RangeBreakdown) {
  std::vector<EvalFrame> frames = {
      frameWith({car(10, 0, 100), car(40, 0, 100)}, {car(10, 0, 0, 0.9f), car(40, 3, 0, 0.8f)})};
  const WaymoResult r = evaluateWaymo(frames);
  EXPECT_NEAR(carResult(r).ranges[0][0].ap, 100.0, 1e-9);
  EXPECT_NEAR(carResult(r).ranges[1][0].ap, 0.0, 1e-9);
  EXPECT_EQ(carResult(r).ranges[2][0].num_gt, 0);
  EXPECT_NEAR(carResult(r).levels[0].ap, 50.0, 1e-9);  // (0.5, 1), (0.5, 0.5)
}

// Greedy and Hungarian matching differ. Cars along x (yaw 0): ground truth A at x = 0 and B at x = 1; prediction P1 (0.9) at x = 0.45
// reaches the 0.7 threshold on both (IoU 0.798 with A, 0.758 with B), P2 (0.8) at x = -0.3 only on A (0.860; 0.509
// with B). Greedy: P1 takes A, P2 finds A taken and is a FP: (0.5, 1), (0.5, 0.5) -> AP 50. Hungarian, at cutoff
// 0.9: P1 - A, (0.5, 1); at cutoff 0.8: P1 - B and P2 - A (total IoU 1.618 > 0.798), (1, 1) -> AP 100.
TEST(WaymoAp, HungarianMatchingGivesTheHigherScoredPredictionUpWhenThatMatchesMore) {
  const std::vector<EvalFrame> frames = {
      frameWith({car(0, 0, 100, 1, 0), car(1, 0, 100, 1, 0)}, {car(0.45, 0, 0, 0.9f, 0), car(-0.3, 0, 0, 0.8f, 0)})};
  ASSERT_GE(iou3d(frames[0].pred_boxes[0], frames[0].gt_boxes[1]), 0.7);  // the premise: P1 could take either,
  ASSERT_GT(iou3d(frames[0].pred_boxes[0], frames[0].gt_boxes[0]),         // greedy takes A
            iou3d(frames[0].pred_boxes[0], frames[0].gt_boxes[1]));
  ASSERT_LT(iou3d(frames[0].pred_boxes[1], frames[0].gt_boxes[1]), 0.7);  // P2 can only take A
  const WaymoResult r = evaluateWaymo(frames);
  const WaymoCurve& c = carResult(r).levels[0];
  EXPECT_EQ(c.num_tp, 2);
  EXPECT_EQ(c.num_fp, 0);
  EXPECT_EQ(c.recall, (std::vector<double>{0.5, 1.0}));
  EXPECT_EQ(c.precision, (std::vector<double>{1.0, 1.0}));
  EXPECT_NEAR(c.ap, 100.0, 1e-9);
  EXPECT_NEAR(c.aph, 100.0, 1e-9);  // same yaw everywhere
}

// The matching is redone at each cutoff. With a third prediction P3 (0.6) at x = 1.3 (IoU 0.860 with B, 0.509 with A),
// the cutoff 0.6 assigns P2 - A and P3 - B (1.72) and P1 becomes the FP: (0.5, 1), (1, 1), (1, 2/3).
TEST(WaymoAp, EachCutoffIsMatchedOnItsOwn) {
  const std::vector<EvalFrame> frames = {frameWith(
      {car(0, 0, 100, 1, 0), car(1, 0, 100, 1, 0)},
      {car(0.45, 0, 0, 0.9f, 0), car(-0.3, 0, 0, 0.8f, 0), car(1.3, 0, 0, 0.6f, 0)})};
  const WaymoResult r = evaluateWaymo(frames);
  const WaymoCurve& c = carResult(r).levels[0];
  EXPECT_EQ(c.num_tp, 2);
  EXPECT_EQ(c.num_fp, 1);
  EXPECT_EQ(c.recall, (std::vector<double>{0.5, 1.0, 1.0}));
  EXPECT_NEAR(c.precision.back(), 2.0 / 3.0, 1e-12);
  EXPECT_NEAR(c.ap, 100.0, 1e-9);
}

// A prediction on a Van (ignored for Car) is neither TP nor FP.
TEST(WaymoAp, IgnoredGroundTruthAbsorbsItsPrediction) {
  EvalFrame f = frameWith({car(10, 0, 100), car(20, 0, 100)}, {car(10, 0, 0, 0.5f), car(20, 0, 0, 0.9f)});
  f.gt_ignore = {0, 1};
  const WaymoResult r = evaluateWaymo({f});
  EXPECT_EQ(carResult(r).levels[0].num_gt, 1);
  EXPECT_EQ(carResult(r).levels[0].num_fp, 0);
  EXPECT_NEAR(carResult(r).levels[0].ap, 100.0, 1e-9);
}

}  // namespace
}  // namespace eval
}  // namespace ret3d
