#include "ret3d/eval/kitti_ap.h"

#include <gtest/gtest.h>

#include <chrono>
#include <cmath>

#include "ret3d/eval/eval_data.h"
#include "support/test_util.h"

namespace ret3d {
namespace eval {
namespace {

kitti::Label car(double x1, double y1, double x2, double y2, double x, double z, double ry = 0) {
  kitti::Label l;
  l.type = "Car";
  l.bbox = {x1, y1, x2, y2};
  l.h = 1.5;
  l.w = 1.6;
  l.l = 4.0;
  l.x = x;
  l.y = 1.7;
  l.z = z;
  l.rotation_y = ry;
  l.alpha = ry;
  return l;
}

kitti::Label scored(kitti::Label l, double s) {
  l.score = s;
  return l;
}

const KittiClassResult& carResult(const KittiResult& r) { return r.classes.at(0); }

TEST(KittiOverlap, MatchesHandComputedValues) {
  // Image: two 10x10 boxes shifted by 5 px: intersection 50, union 150.
  kitti::Label a = car(0, 0, 10, 10, 0, 10), b = car(5, 0, 15, 10, 0, 10);
  EXPECT_NEAR(kittiImageOverlap(a, b), 1.0 / 3.0, 1e-12);
  EXPECT_NEAR(kittiImageOverlap(a, b, 0), 0.5, 1e-12);  // over the detection's area
  // BEV: same box moved 2 m along its length (camera x at ry = 0): overlap 2 x 1.6 of 4 x 1.6 each -> 1/3.
  kitti::Label c = car(0, 0, 10, 10, 2, 10);
  EXPECT_NEAR(kittiBevOverlap(a, c), 3.2 / (6.4 + 6.4 - 3.2), 1e-9);
  // Rotated by pi/2 the length runs along z: that box spans x [-0.8, 0.8], z [8, 12]; the unrotated one at x = 2
  // spans x [0, 4], z [9.2, 10.8]: overlap 0.8 (x) by 1.6 (z).
  kitti::Label d = car(0, 0, 10, 10, 0, 10, M_PI / 2);
  kitti::Label e = car(0, 0, 10, 10, 2, 10, 0);
  EXPECT_NEAR(kittiBevOverlap(d, e), 0.8 * 1.6 / (6.4 + 6.4 - 0.8 * 1.6), 1e-9);
  // 3D: half the height overlaps (y is the bottom, boxes span [y - h, y]).
  kitti::Label f = a;
  f.y = a.y - 0.75;
  EXPECT_NEAR(kitti3dOverlap(a, f), (6.4 * 0.75) / (2 * 6.4 * 1.5 - 6.4 * 0.75), 1e-9);
}

// The devkit places one recall sample per score threshold it keeps, so a perfect result reaches AP 100 only with
// more than 40 ground-truth objects (with fewer, the samples beyond the last threshold stay 0): use 80.
TEST(KittiAp, PerfectPredictionsGive100AndNoneGive0) {
  std::vector<KittiFrame> frames(40);
  for (int i = 0; i < 40; ++i) {
    frames[i].gt = {car(100, 150, 200, 250, -3, 10 + 0.1 * i), car(400, 150, 480, 230, 4, 20 + 0.1 * i)};
    for (const auto& g : frames[i].gt) frames[i].det.push_back(scored(g, 0.5 + 0.01 * i));
  }
  const KittiResult perfect = evaluateKitti(frames);
  for (int m = 0; m < kKittiNumMetrics; ++m) {
    for (int d = 0; d < kKittiNumDifficulties; ++d) {
      EXPECT_NEAR(carResult(perfect).curves[m][d].ap11(), 100.0, 1e-9);
      EXPECT_NEAR(carResult(perfect).curves[m][d].ap40(), 100.0, 1e-9);
    }
  }
  EXPECT_NEAR(carResult(perfect).aos[0].ap40(), 100.0, 1e-9);
  for (auto& f : frames) f.det.clear();
  const KittiResult none = evaluateKitti(frames);
  EXPECT_EQ(carResult(none).curves[2][0].num_gt, 80);
  EXPECT_DOUBLE_EQ(carResult(none).curves[2][0].ap11(), 0.0);
  EXPECT_DOUBLE_EQ(carResult(none).curves[2][0].ap40(), 0.0);
}

// Four easy cars in four frames; detections with scores 0.9 (hit), 0.8 (false positive), 0.7 (hit), and nothing
// for the other two cars. TP scores {0.9, 0.7}, n_gt = 4: getThresholds keeps both (recall 1/4 and 2/4).
// At threshold 0.9: TP 1, FP 0 -> precision 1; at 0.7: TP 2, FP 1 -> precision 2/3. The 41-point curve is
// [1, 2/3, 0, ..., 0] after the max filter (only two thresholds exist).
// R11 = (p[0] + p[4] + ... + p[40]) / 11 = 1/11 = 9.0909...; R40 = (p[1] + ... + p[40]) / 40 = (2/3)/40 = 1.6667.
TEST(KittiAp, CraftedCaseR11AndR40) {
  std::vector<KittiFrame> frames(4);
  for (int i = 0; i < 4; ++i) frames[i].gt = {car(100, 150, 200, 250, -3, 10)};
  frames[0].det = {scored(car(100, 150, 200, 250, -3, 10), 0.9)};
  frames[1].det = {scored(car(600, 150, 700, 250, 8, 10), 0.8)};  // nowhere near the car: FP
  frames[2].det = {scored(car(100, 150, 200, 250, -3, 10), 0.7)};
  const KittiResult r = evaluateKitti(frames);
  const KittiCurve& c = carResult(r).curves[static_cast<int>(KittiMetric::Box3D)][0];
  ASSERT_EQ(c.thresholds.size(), 2u);
  EXPECT_NEAR(c.precision[0], 1.0, 1e-12);
  EXPECT_NEAR(c.precision[1], 2.0 / 3.0, 1e-12);
  EXPECT_NEAR(c.ap11(), 100.0 / 11.0, 1e-9);
  EXPECT_NEAR(c.ap40(), 100.0 * (2.0 / 3.0) / 40.0, 1e-9);
}

// Exact recall sampling (KittiApOptions::exact_recall), on the crafted case above: recall 1/4 at precision 1, 2/4 at
// 2/3. Precision at recall k/40: 1 for k <= 10, 2/3 for 10 < k <= 20, 0 beyond. R40 = (10 + 10 * 2/3) / 40 = 41.67;
// R11 (k = 0, 4, ..., 40): k = 0, 4, 8 -> 1; 12, 16, 20 -> 2/3; the rest 0: (3 + 2) / 11 = 45.45.
// And six perfectly detected cars: 100 with exact sampling, where the devkit's sampling caps them at 5/40 = 12.5.
TEST(KittiAp, ExactRecallSamplingForSmallSets) {
  std::vector<KittiFrame> frames(4);
  for (int i = 0; i < 4; ++i) frames[i].gt = {car(100, 150, 200, 250, -3, 10)};
  frames[0].det = {scored(car(100, 150, 200, 250, -3, 10), 0.9)};
  frames[1].det = {scored(car(600, 150, 700, 250, 8, 10), 0.8)};
  frames[2].det = {scored(car(100, 150, 200, 250, -3, 10), 0.7)};
  KittiApOptions o;
  o.exact_recall = true;
  const KittiResult r = evaluateKitti(frames, o);  // kept: the curve is a reference into it
  const KittiCurve& c = carResult(r).curves[static_cast<int>(KittiMetric::Box3D)][0];
  EXPECT_NEAR(c.ap40(), 100.0 * (10 + 10 * 2.0 / 3.0) / 40.0, 1e-9);
  EXPECT_NEAR(c.ap11(), 100.0 * (3 + 2) / 11.0, 1e-9);

  std::vector<KittiFrame> six(6);
  for (int i = 0; i < 6; ++i) {
    six[i].gt = {car(100, 150, 200, 250, -3, 10 + i)};
    six[i].det = {scored(six[i].gt[0], 0.5 + 0.05 * i)};
  }
  EXPECT_NEAR(carResult(evaluateKitti(six)).curves[2][1].ap40(), 100.0 * 5 / 40, 1e-9);
  EXPECT_NEAR(carResult(evaluateKitti(six, o)).curves[2][1].ap40(), 100.0, 1e-9);
  // On many objects the two samplings agree (the devkit's holds from 40 objects on).
  std::vector<KittiFrame> many(80);
  for (int i = 0; i < 80; ++i) {
    many[i].gt = {car(100, 150, 200, 250, -3, 10)};
    if (i % 4 != 3) many[i].det = {scored(many[i].gt[0], 0.9 - 0.001 * i)};
    if (i % 5 == 0) many[i].det.push_back(scored(car(600, 150, 700, 250, 8, 10), 0.95 - 0.001 * i));
  }
  const double devkit = carResult(evaluateKitti(many)).curves[2][0].ap40();
  const double exact = carResult(evaluateKitti(many, o)).curves[2][0].ap40();
  EXPECT_NEAR(exact, devkit, 3.0);
}

// False boxes: a detection on no label of any type (here a Truck, a Misc and a DontCare region are labelled) counts;
// one on the truck (wrong class) or inside the DontCare region does not.
TEST(KittiAp, FalseBoxesAreThoseOnNoLabel) {
  KittiFrame f;
  kitti::Label truck = car(300, 150, 400, 250, 6, 30);
  truck.type = "Truck";
  kitti::Label dontcare = car(700, 150, 800, 250, 0, 0);
  dontcare.type = "DontCare";
  f.gt = {car(100, 150, 200, 250, -3, 10), truck, dontcare};
  f.det = {scored(car(100, 150, 200, 250, -3, 10), 0.9),  // on the car
           scored(car(300, 150, 400, 250, 6, 30), 0.8),   // on the truck
           scored(car(700, 150, 800, 250, 15, 40), 0.7),  // in the DontCare region's image box
           scored(car(500, 150, 560, 250, -10, 25), 0.6), // on nothing: false
           scored(car(500, 150, 560, 250, 10, 50), 0.2)}; // on nothing, low score: false
  const KittiResult r = evaluateKitti({f, KittiFrame{}});
  EXPECT_EQ(r.false_boxes.per_class[0], 2);
  EXPECT_EQ(r.false_boxes.per_class_score50[0], 1);
  EXPECT_EQ(r.false_boxes.total(), 2);
}

// Devkit rules, on 80 copies of one frame (see above: 40 objects are not enough for 41 samples): a car (easy), a
// Van, a DontCare region and a heavily occluded car (hard only). Detections: the car (score 0.9); at 0.95 the Van,
// the occluded car, one inside the DontCare region's image box but far from everything in 3D, and a 20 px tall one
// (below every minimum height).
//   2D easy: the Van's and the occluded car's detections hit ignored ground truth, the DontCare region masks its
//     detection, the small one is ignored: 80 TP, 0 FP -> AP 100.
//   BEV easy: DontCare has no ground-plane geometry (-1000), so its detection is a FP at 0.95: precision 80/160 at
//     every threshold -> R11 = R40 = 50.
//   BEV hard: the occluded cars count (n_gt 160, TP at 0.95 and 0.9); at 0.95 precision 80/160, at 0.9 160/240;
//     the max-to-the-right filter gives 2/3 everywhere -> 66.67. 2D hard: 100.
TEST(KittiAp, IgnoreRulesOfTheDevkit) {
  KittiFrame f;
  f.gt = {car(100, 150, 200, 250, -3, 10)};
  kitti::Label van = car(300, 150, 400, 250, 3, 10);
  van.type = "Van";
  kitti::Label dontcare = car(500, 150, 600, 250, 0, 0);
  dontcare.type = "DontCare";
  dontcare.x = dontcare.y = dontcare.z = -1000;
  kitti::Label occluded = car(700, 150, 800, 250, 8, 10);
  occluded.occluded = 2;
  f.gt.push_back(van);
  f.gt.push_back(dontcare);
  f.gt.push_back(occluded);
  f.det = {scored(car(100, 150, 200, 250, -3, 10), 0.9), scored(car(300, 150, 400, 250, 3, 10), 0.95),
           scored(car(505, 155, 595, 245, 0, 30), 0.95), scored(car(700, 150, 800, 250, 8, 10), 0.95),
           scored(car(900, 150, 950, 170, 12, 40), 0.95)};
  const KittiResult r = evaluateKitti(std::vector<KittiFrame>(80, f));
  const auto& img = carResult(r).curves[static_cast<int>(KittiMetric::Box2D)];
  const auto& bev = carResult(r).curves[static_cast<int>(KittiMetric::Bev)];
  EXPECT_EQ(img[0].num_gt, 80);
  EXPECT_EQ(img[2].num_gt, 160);
  EXPECT_NEAR(img[0].ap11(), 100.0, 1e-9);
  EXPECT_NEAR(img[0].ap40(), 100.0, 1e-9);
  EXPECT_NEAR(img[2].ap40(), 100.0, 1e-9);
  EXPECT_NEAR(bev[0].ap11(), 50.0, 1e-9);
  EXPECT_NEAR(bev[0].ap40(), 50.0, 1e-9);
  EXPECT_NEAR(bev[2].ap40(), 200.0 / 3.0, 1e-9);
}

// ---- acceptance: the official devkit's figures on the PointRCNN detections (../shared/data/REFERENCE_AP.md) ----

struct Reference {
  ObjectClass cls;
  const char* metric;  // "3d", "bev", "2d", "aos"
  double r11[3];
  double r40[3];  // NaN when the table has none
};

constexpr double kNone = NAN;
const Reference kReference[] = {
    {ObjectClass::Car, "3d", {90.40, 84.87, 79.94}, {96.12, 86.47, 83.90}},
    {ObjectClass::Car, "bev", {99.82, 90.84, 90.80}, {99.92, 94.78, 92.31}},
    {ObjectClass::Car, "2d", {96.89, 90.26, 89.92}, {kNone, kNone, kNone}},
    {ObjectClass::Car, "aos", {96.88, 90.18, 89.79}, {kNone, kNone, kNone}},
    {ObjectClass::Pedestrian, "3d", {75.80, 72.13, 67.24}, {76.84, 72.99, 67.49}},
    {ObjectClass::Pedestrian, "bev", {81.65, 81.38, 72.57}, {84.56, 82.01, 76.89}},
    {ObjectClass::Pedestrian, "2d", {74.10, 71.43, 66.42}, {kNone, kNone, kNone}},
    {ObjectClass::Cyclist, "3d", {83.48, 79.81, 78.30}, {86.39, 81.45, 79.16}},
    {ObjectClass::Cyclist, "bev", {99.01, 90.24, 89.94}, {99.24, 91.88, 89.43}},
    {ObjectClass::Cyclist, "2d", {90.99, 84.24, 82.14}, {kNone, kNone, kNone}},
};

const KittiCurve& curveFor(const KittiClassResult& c, const std::string& metric, int d) {
  if (metric == "aos") return c.aos[d];
  if (metric == "2d") return c.curves[0][d];
  if (metric == "bev") return c.curves[1][d];
  return c.curves[2][d];
}

TEST(KittiApReference, ReproducesTheOfficialDevkitOnPointRcnn) {
  const auto shared = test::sharedDataDir();
  if (!shared) GTEST_SKIP() << test::kSharedDataMissing;
  const std::string root = *shared + "/kitti_tracking";
  EvalData data = loadKittiTracking(root + "/training", root + "/detections/pointrcnn", parseSequenceList("1-20"));
  ASSERT_EQ(data.frames.size(), 7854u);
  std::vector<KittiFrame> frames;
  for (auto& f : data.frames) frames.push_back({f.gt_labels, f.pred_labels});

  const auto t0 = std::chrono::steady_clock::now();
  const KittiResult r = evaluateKitti(frames);
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  std::printf("KITTI AP over %zu frames: %.2f s (2 threads)\n", frames.size(), seconds);
  ASSERT_TRUE(r.aos_valid);
  for (const auto& ref : kReference) {
    const KittiClassResult& c = r.classes.at(static_cast<int>(ref.cls) - 1);
    ASSERT_EQ(c.cls, ref.cls);
    for (int d = 0; d < 3; ++d) {
      const KittiCurve& curve = curveFor(c, ref.metric, d);
      std::printf("%-10s %-3s %-8s R11 ref %6.2f ours %8.4f", className(ref.cls), ref.metric,
                  difficultyKey(static_cast<KittiDifficulty>(d)), ref.r11[d], curve.ap11());
      if (!std::isnan(ref.r40[d])) std::printf("   R40 ref %6.2f ours %8.4f", ref.r40[d], curve.ap40());
      std::printf("\n");
      EXPECT_NEAR(curve.ap11(), ref.r11[d], 0.1) << className(ref.cls) << " " << ref.metric << " R11 " << d;
      if (!std::isnan(ref.r40[d])) {
        EXPECT_NEAR(curve.ap40(), ref.r40[d], 0.1) << className(ref.cls) << " " << ref.metric << " R40 " << d;
      }
    }
  }
}

}  // namespace
}  // namespace eval
}  // namespace ret3d
