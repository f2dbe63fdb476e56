#include "ret3d/eval/mot_metrics.h"

#include <gtest/gtest.h>

#include <cmath>
#include <map>

#include "support/boxes.h"
#include "support/test_util.h"

namespace ret3d {
namespace eval {
namespace {

Box car(double x, double y, std::uint32_t id) {
  Box b = test::carBox(x, y);
  b.track_id = id;
  return b;
}

// Two ground-truth cars over 10 frames: A (id 1) at y = 0 and B (id 2) at y = 10, both moving along x.
std::vector<EvalFrame> groundTruth(int n = 10) {
  std::vector<EvalFrame> frames(n);
  for (int t = 0; t < n; ++t) {
    frames[t].sequence = "0000";
    frames[t].frame = t;
    frames[t].gt_boxes = {car(t, 0, 1), car(t, 10, 2)};
    frames[t].gt_ignore = {0, 0};
  }
  return frames;
}

const MotClassResult& carResult(const MotResult& r) { return r.classes.at(0); }

TEST(MotMetrics, PerfectTrackingScoresFull) {
  auto frames = groundTruth();
  for (auto& f : frames) f.pred_boxes = {car(f.frame, 0, 7), car(f.frame, 10, 8)};  // any ids, kept throughout
  const MotResult res = evaluateMot(frames);
  const auto& r = carResult(res);
  EXPECT_NEAR(r.clear.mota, 100.0, 1e-9);
  EXPECT_NEAR(r.clear.motp, 100.0, 1e-6);
  EXPECT_EQ(r.clear.idsw, 0);
  EXPECT_EQ(r.clear.frag, 0);
  EXPECT_EQ(r.clear.mt, 2);
  EXPECT_EQ(r.clear.ml, 0);
  EXPECT_NEAR(r.hota.hota, 100.0, 1e-6);
  EXPECT_NEAR(r.hota.deta, 100.0, 1e-6);
  EXPECT_NEAR(r.hota.assa, 100.0, 1e-6);
}

TEST(MotMetrics, NoPredictionsScoreZero) {
  const MotResult res = evaluateMot(groundTruth());
  const auto& r = carResult(res);
  EXPECT_DOUBLE_EQ(r.clear.mota, 0.0);
  EXPECT_EQ(r.clear.fn, 20);
  EXPECT_EQ(r.clear.mt, 0);
  EXPECT_EQ(r.clear.ml, 2);
  EXPECT_DOUBLE_EQ(r.hota.hota, 0.0);
  EXPECT_DOUBLE_EQ(r.hota.deta, 0.0);
}

// A is followed by id 7 in frames 0-4 and by id 9 in frames 5-9 (B perfectly by 8): one switch, counted once.
// MOTA = (TP - FP - IDSW) / GT = (20 - 0 - 1) / 20 = 95. HOTA: every alpha has TP 20; AssA = (A-7: 5 matches,
// Jaccard 5 / (10 + 5 - 5) = 0.5, 5 x 0.5; A-9 likewise; B-8: 10 x 1) / 20 = 15 / 20 = 0.75; DetA = 1;
// HOTA = sqrt(0.75) = 86.60.
TEST(MotMetrics, OneIdSwitchCountedOnce) {
  auto frames = groundTruth();
  for (auto& f : frames) f.pred_boxes = {car(f.frame, 0, f.frame < 5 ? 7 : 9), car(f.frame, 10, 8)};
  const MotResult res = evaluateMot(frames);
  const auto& r = carResult(res);
  EXPECT_EQ(r.clear.idsw, 1);
  EXPECT_EQ(r.clear.frag, 0);
  EXPECT_NEAR(r.clear.mota, 95.0, 1e-9);
  EXPECT_NEAR(r.hota.deta, 100.0, 1e-6);
  EXPECT_NEAR(r.hota.assa, 75.0, 1e-6);
  EXPECT_NEAR(r.hota.hota, 100.0 * std::sqrt(0.75), 1e-6);
}

// A's prediction is missing in frames 4 and 5, then resumes with the same id: one fragmentation, no switch.
// MOTA = (18 - 0 - 0) / 20 = 90; A is tracked 8/10 = 0.8 (not > 0.8): partly tracked, B mostly tracked.
// HOTA: DetA = 18 / 20 = 0.9; AssA = (A-7: 8 x 8 / (10 + 8 - 8) + B-8: 10 x 1) / 18 = 16.4 / 18;
// HOTA = sqrt(0.9 x 16.4 / 18) = sqrt(0.82) = 90.55.
TEST(MotMetrics, BrokenAndResumedTrackIsOneFragmentation) {
  auto frames = groundTruth();
  for (auto& f : frames) {
    f.pred_boxes = {car(f.frame, 10, 8)};
    if (f.frame != 4 && f.frame != 5) f.pred_boxes.push_back(car(f.frame, 0, 7));
  }
  const MotResult res = evaluateMot(frames);
  const auto& r = carResult(res);
  EXPECT_EQ(r.clear.frag, 1);
  EXPECT_EQ(r.clear.idsw, 0);
  EXPECT_EQ(r.clear.fn, 2);
  EXPECT_NEAR(r.clear.mota, 90.0, 1e-9);
  EXPECT_EQ(r.clear.mt, 1);
  EXPECT_EQ(r.clear.pt, 1);
  EXPECT_EQ(r.clear.ml, 0);
  EXPECT_NEAR(r.hota.deta, 90.0, 1e-6);
  EXPECT_NEAR(r.hota.assa, 100.0 * 16.4 / 18.0, 1e-6);
  EXPECT_NEAR(r.hota.hota, 100.0 * std::sqrt(0.82), 1e-6);
}

// The same gap in frames where the tracker output nothing at all still counts (TrackEval would skip those frames).
TEST(MotMetrics, GapInEmptyFramesIsAlsoAFragmentation) {
  auto frames = groundTruth();
  for (auto& f : frames) {
    f.gt_boxes.resize(1);
    f.gt_ignore.resize(1);
    if (f.frame != 4 && f.frame != 5) f.pred_boxes = {car(f.frame, 0, 7)};
  }
  const MotResult res = evaluateMot(frames);
  const auto& r = carResult(res);
  EXPECT_EQ(r.clear.frag, 1);
  EXPECT_NEAR(r.clear.mota, 80.0, 1e-9);
}

// Perfect tracks plus a false track (id 99, frames 0-4, far from everything) and a second false track (id 98,
// frames 0-9): FP = 15. MOTA = (20 - 15) / 20 = 25. HOTA: DetA = 20 / (20 + 15) = 4/7; AssA = 1;
// HOTA = sqrt(4/7) = 75.59. MOTP stays 100.
TEST(MotMetrics, InjectedFalseTracks) {
  auto frames = groundTruth();
  for (auto& f : frames) {
    f.pred_boxes = {car(f.frame, 0, 7), car(f.frame, 10, 8), car(f.frame, 50, 98)};
    if (f.frame < 5) f.pred_boxes.push_back(car(f.frame, -40, 99));
  }
  const MotResult res = evaluateMot(frames);
  const auto& r = carResult(res);
  EXPECT_EQ(r.clear.fp, 15);
  EXPECT_NEAR(r.clear.mota, 25.0, 1e-9);
  EXPECT_NEAR(r.clear.motp, 100.0, 1e-6);
  EXPECT_NEAR(r.hota.deta, 100.0 * 4.0 / 7.0, 1e-6);
  EXPECT_NEAR(r.hota.assa, 100.0, 1e-6);
  EXPECT_NEAR(r.hota.hota, 100.0 * std::sqrt(4.0 / 7.0), 1e-6);
  EXPECT_EQ(r.num_pred_tracks, 4);
}

// A prediction on an ignored box (a Van, evaluated as Car) is removed, not a false positive.
TEST(MotMetrics, PredictionsOnIgnoredGroundTruthAreRemoved) {
  auto frames = groundTruth();
  for (auto& f : frames) {
    f.gt_boxes.push_back(car(f.frame, 20, 3));
    f.gt_ignore.push_back(1);
    f.pred_boxes = {car(f.frame, 0, 7), car(f.frame, 10, 8), car(f.frame, 20, 9)};
  }
  const MotResult all = evaluateMot(frames);
  EXPECT_EQ(all.removed_on_ignore, 10u);
  EXPECT_EQ(carResult(all).clear.fp, 0);
  EXPECT_NEAR(carResult(all).clear.mota, 100.0, 1e-9);
}

// max_range leaves out what lies beyond it, ground truth and predictions alike: a missed far car (frames 0-9 at x =
// 60 + t) and a false far track (x = -55) stop counting, while a near false positive still does.
TEST(MotMetrics, MaxRangeLeavesOutFarBoxes) {
  auto frames = groundTruth();
  for (auto& f : frames) {
    f.gt_boxes.push_back(car(60 + f.frame, 0, 3));
    f.gt_ignore.push_back(0);
    f.pred_boxes = {car(f.frame, 0, 7), car(f.frame, 10, 8), car(-55, 0, 9)};
    if (f.frame == 0) f.pred_boxes.push_back(car(0, -20, 10));
  }
  const MotResult all = evaluateMot(frames);
  EXPECT_EQ(carResult(all).clear.fn, 10);
  EXPECT_EQ(carResult(all).clear.fp, 11);
  EXPECT_NEAR(carResult(all).clear.mota, 100.0 * (1 - 21.0 / 30.0), 1e-9);
  MotOptions o;
  o.max_range = 50;
  const MotResult near = evaluateMot(frames, o);
  EXPECT_EQ(carResult(near).clear.num_gt, 20);
  EXPECT_EQ(carResult(near).clear.fn, 0);
  EXPECT_EQ(carResult(near).clear.fp, 1);
  EXPECT_NEAR(carResult(near).clear.mota, 95.0, 1e-9);
  EXPECT_EQ(carResult(near).num_pred_tracks, 3);
}

TEST(MotMetrics, CentreDistanceSimilarity) {
  MotOptions o;
  o.similarity = MotSimilarity::CenterDistance;
  o.zero_distance = 2.0;
  EXPECT_NEAR(motSimilarity(car(0, 0, 1), car(0.5, 0, 1), o), 0.75, 1e-12);
  EXPECT_NEAR(motSimilarity(car(0, 0, 1), car(3, 0, 1), o), 0.0, 1e-12);
  // A's prediction 1.45 m off every frame: similarity 0.275 < 0.5, so no CLEAR match; HOTA matches it for alpha up
  // to 0.25.
  auto frames = groundTruth();
  for (auto& f : frames) f.pred_boxes = {car(f.frame + 1.45, 0, 7), car(f.frame, 10, 8)};
  o.classes = {ObjectClass::Car};
  const MotResult res = evaluateMot(frames, o);
  const auto& r = carResult(res);
  EXPECT_EQ(r.clear.tp, 10);
  EXPECT_EQ(r.clear.fp, 10);
  // DetA per alpha: alphas 0.05..0.25 (5 of 19) have 20 TP; the rest 10 TP, 10 FN, 10 FP -> 1/3.
  EXPECT_NEAR(r.hota.deta, 100.0 * (5 * 1.0 + 14 * (1.0 / 3.0)) / 19.0, 1e-6);
}

TEST(MotMetrics, MissingTrackIdIsAnError) {
  auto frames = groundTruth();
  frames[3].pred_boxes = {car(3, 0, 0)};
  EXPECT_THROW(evaluateMot(frames), std::invalid_argument);
}

// Real ground truth (KITTI tracking sequence 0001) as predictions, then with injected errors whose effect is
// known: an ID switch in the middle of the longest car track (+1 IDSW), a two-frame gap in another car track
// (+2 FN, +1 FRAG), and a false track of 20 frames far from everything (+20 FP).
TEST(MotMetrics, RealGroundTruthWithInjectedErrors) {
  const auto shared = test::sharedDataDir();
  if (!shared) GTEST_SKIP() << test::kSharedDataMissing;
  EvalData data = loadKittiTracking(*shared + "/kitti_tracking/training", "", {"0001"});
  MotOptions o;
  o.classes = {ObjectClass::Car};
  std::map<std::uint32_t, std::vector<int>> car_frames;  // track id -> frames where it is a (non-ignored) car
  for (auto& f : data.frames) {
    f.pred_boxes.clear();
    for (std::size_t g = 0; g < f.gt_boxes.size(); ++g) {
      if (f.gt_ignore[g]) continue;
      Box p = f.gt_boxes[g];
      p.track_id += 1000;
      f.pred_boxes.push_back(p);
      if (p.label == ObjectClass::Car) car_frames[f.gt_boxes[g].track_id].push_back(f.frame);
    }
  }
  const MotResult base_all = evaluateMot(data.frames, o);
  const ClearMot base = base_all.classes[0].clear;
  EXPECT_NEAR(base.mota, 100.0, 1e-9);
  EXPECT_EQ(base.idsw, 0);
  EXPECT_NEAR(base_all.classes[0].hota.hota, 100.0, 1e-6);

  // The longest car track gets a new id from its middle frame on.
  std::uint32_t longest = 0;
  for (const auto& [id, fr] : car_frames) {
    if (!longest || fr.size() > car_frames[longest].size()) longest = id;
  }
  const int switch_at = car_frames[longest][car_frames[longest].size() / 2];
  // Another car track seen in three consecutive frames a, a+1, a+2 (and on): drop its prediction in a+1 and a+2,
  // then it resumes at a+3.
  std::uint32_t gapped = 0;
  int gap_at = -1;
  for (const auto& [id, fr] : car_frames) {
    if (id == longest) continue;
    for (std::size_t k = 0; k + 3 < fr.size(); ++k) {
      if (fr[k + 3] == fr[k] + 3) {
        gapped = id;
        gap_at = fr[k] + 1;
        break;
      }
    }
    if (gapped) break;
  }
  ASSERT_TRUE(gapped);
  for (auto& f : data.frames) {
    std::vector<Box> kept;
    for (Box p : f.pred_boxes) {
      if (p.track_id == longest + 1000 && f.frame >= switch_at) p.track_id = 5000;
      if (p.track_id == gapped + 1000 && (f.frame == gap_at || f.frame == gap_at + 1)) continue;
      kept.push_back(p);
    }
    if (f.frame < 20) {
      Box ghost = kept.empty() ? Box() : kept.front();
      ghost.x = 200.0;
      ghost.y = 200.0;
      ghost.label = ObjectClass::Car;
      ghost.track_id = 9999;
      kept.push_back(ghost);
    }
    f.pred_boxes = kept;
  }
  const ClearMot c = evaluateMot(data.frames, o).classes[0].clear;
  EXPECT_EQ(c.idsw, base.idsw + 1);
  EXPECT_EQ(c.frag, base.frag + 1);
  EXPECT_EQ(c.fn, base.fn + 2);
  EXPECT_EQ(c.fp, base.fp + 20);
  const int gt = base.num_gt;
  EXPECT_NEAR(c.mota, 100.0 * ((gt - 2) - 20 - 1) / gt, 1e-9);
}

}  // namespace
}  // namespace eval
}  // namespace ret3d
