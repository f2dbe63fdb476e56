// `ret3d eval --min-points`: ground truth holding too few returns of its scan is ignored by every metric.
#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "ret3d/core/geometry.h"
#include "ret3d/eval/eval_data.h"
#include "ret3d/eval/kitti_ap.h"
#include "ret3d/eval/mot_metrics.h"
#include "ret3d/eval/report.h"
#include "ret3d/eval/waymo_ap.h"
#include "support/test_util.h"

namespace ret3d {
namespace eval {
namespace {

kitti::Label car(double x, double z, int track) {
  kitti::Label l;
  l.type = "Car";
  l.bbox = {600 + 40 * x, 150, 700 + 40 * x, 230};  // 80 px high, unoccluded: every KITTI difficulty
  l.h = 1.5, l.w = 1.6, l.l = 4.0;
  l.x = x, l.y = 1.7, l.z = z;
  l.rotation_y = 0.3;
  l.alpha = 0.3;
  l.track_id = track;
  return l;
}

kitti::Label scored(kitti::Label l, double s) {
  l.score = s;
  return l;
}

// A point at (u, v, w) in the box's own axes (fractions of the half sizes; > 1 is outside), plus `out` metres along u.
Point pointOf(const Box& b, double u, double v, double w, double out = 0) {
  const double c = std::cos(b.yaw), s = std::sin(b.yaw);
  const double du = u * b.length / 2 + out, dv = v * b.width / 2;
  Point p;
  p.x = static_cast<float>(b.x + c * du - s * dv);
  p.y = static_cast<float>(b.y + s * du + c * dv);
  p.z = static_cast<float>(b.z + w * b.height / 2);
  p.intensity = 0.5f;
  return p;
}

// Two cars per frame: a dense one (40 returns) and a sparse one (3 returns inside, 2 within the 0.1 m margin, one
// 0.3 m off its end); `pred_sparse` adds a prediction on the sparse one, scored above the dense one's.
class MinPoints : public ::testing::Test {
 protected:
  EvalData makeData(bool pred_sparse, int frames = 2) {
    EvalData data;
    const kitti::Calibration calib = kitti::defaultCalibration();
    for (int f = 0; f < frames; ++f) {
      EvalFrame fr;
      fr.sequence = "0000";
      fr.frame = f;
      fr.gt_labels = {car(-3, 15, 0), car(4, 25, 1)};
      fr.pred_labels = {scored(fr.gt_labels[0], 0.5)};
      if (pred_sparse) fr.pred_labels.push_back(scored(fr.gt_labels[1], 0.9));
      fillGtBoxesFromLabels(fr, calib);
      fillPredBoxesFromLabels(fr, calib);
      PointCloud cloud;
      const Box& dense = fr.gt_boxes[0];
      for (int i = 0; i < 40; ++i) cloud.points.push_back(pointOf(dense, -0.9 + 0.045 * i, 0.5, (i % 3) * 0.4 - 0.4));
      const Box& sparse = fr.gt_boxes[1];
      for (double u : {-0.5, 0.0, 0.5}) cloud.points.push_back(pointOf(sparse, u, 0, 0));
      cloud.points.push_back(pointOf(sparse, 1.0, 0, 0, 0.05));    // 5 cm beyond its front: a return of it
      cloud.points.push_back(pointOf(sparse, -1.0, 0, 0, -0.08));  // 8 cm behind its back: a return of it
      cloud.points.push_back(pointOf(sparse, 1.0, 0, 0, 0.3));     // 30 cm off: not
      fr.velodyne_path = dir_ / ("scan" + std::to_string(f) + ".bin");
      kitti::writeVelodyne(fr.velodyne_path, cloud);
      data.frames.push_back(std::move(fr));
    }
    data.gt_has_track_ids = data.pred_has_track_ids = true;
    return data;
  }

  static const WaymoCurve& waymoCar(const EvalData& d) {
    static WaymoResult r;
    WaymoOptions o;
    o.use_point_counts = false;
    r = evaluateWaymo(d.frames, o);
    return r.classes.at(0).levels[0];
  }

  static KittiCurve kittiCar(const EvalData& d) {
    std::vector<KittiFrame> frames;
    for (const EvalFrame& f : d.frames) frames.push_back({f.gt_labels, f.pred_labels, f.gt_label_ignore});
    KittiApOptions o;
    o.exact_recall = true;
    return evaluateKitti(frames, o).classes.at(0).curves[static_cast<int>(KittiMetric::Box3D)][1];
  }

  test::TempDir dir_;
};

TEST_F(MinPoints, CountsReturnsInTheLabelGrownByTenCentimetres) {
  EvalData d = makeData(false);
  const auto counts = ignoreLabelsWithFewReturns(d, 10);
  ASSERT_EQ(d.frames[0].gt_returns.size(), 2u);
  EXPECT_EQ(d.frames[0].gt_returns[0], 40u);
  EXPECT_EQ(d.frames[0].gt_returns[1], 5u);
  EXPECT_EQ(counts.at(ObjectClass::Car).kept, 2u);  // one per frame
  EXPECT_EQ(counts.at(ObjectClass::Car).ignored, 2u);
  EXPECT_EQ(d.frames[0].gt_ignore, (std::vector<char>{0, 1}));
  EXPECT_EQ(d.frames[0].gt_label_ignore, (std::vector<char>{0, 1}));
  // At 5 the sparse car holds enough.
  EvalData d5 = makeData(false);
  EXPECT_EQ(ignoreLabelsWithFewReturns(d5, 5).at(ObjectClass::Car).ignored, 0u);
}

TEST_F(MinPoints, AnUnmatchedSparseLabelIsNoMiss) {
  EvalData all = makeData(false), counted = makeData(false);
  ignoreLabelsWithFewReturns(counted, 10);
  // Without the rule the sparse car is a miss in every metric.
  EXPECT_EQ(waymoCar(all).num_gt, 4);  // two cars in each of two frames
  EXPECT_NEAR(waymoCar(all).ap, 50.0, 1e-6);
  EXPECT_NEAR(kittiCar(all).ap40(), 50.0, 1e-6);
  EXPECT_EQ(waymoCar(counted).num_gt, 2);
  EXPECT_NEAR(waymoCar(counted).ap, 100.0, 1e-6);
  EXPECT_NEAR(kittiCar(counted).ap40(), 100.0, 1e-6);
  EXPECT_EQ(kittiCar(counted).num_gt, 2);  // one dense car per frame
  MotOptions mo;
  mo.classes = {ObjectClass::Car};
  EXPECT_EQ(evaluateMot(all.frames, mo).classes.at(0).clear.fn, 2);
  const ClearMot c = evaluateMot(counted.frames, mo).classes.at(0).clear;
  EXPECT_EQ(c.fn, 0);
  EXPECT_NEAR(c.mota, 100.0, 1e-6);
}

TEST_F(MinPoints, APredictionOnASparseLabelIsNeitherTrueNorFalse) {
  EvalData d = makeData(true);
  ignoreLabelsWithFewReturns(d, 10);
  const WaymoCurve& w = waymoCar(d);
  EXPECT_EQ(w.num_tp, 2);
  EXPECT_EQ(w.num_fp, 0);
  EXPECT_NEAR(w.ap, 100.0, 1e-6);
  EXPECT_NEAR(kittiCar(d).ap40(), 100.0, 1e-6);
  MotOptions mo;
  mo.classes = {ObjectClass::Car};
  const ClearMot c = evaluateMot(d.frames, mo).classes.at(0).clear;
  EXPECT_EQ(c.tp, 2);
  EXPECT_EQ(c.fp, 0);
}

TEST_F(MinPoints, TheReportListsEveryLabelsReturns) {
  EvalData d = makeData(false);
  EvalReport r;
  r.min_points = 10;
  r.min_points_counts = ignoreLabelsWithFewReturns(d, 10);
  r.label_returns = labelReturns(d);
  ASSERT_EQ(r.label_returns.size(), 4u);
  EXPECT_EQ(r.label_returns[1].returns, 5u);
  EXPECT_TRUE(r.label_returns[1].ignored);
  EXPECT_EQ(r.label_returns[1].track_id, 1);
  const auto m = metricsMap(r);
  EXPECT_EQ(m.at("min_points.threshold"), 10);
  EXPECT_EQ(m.at("min_points.Car.ignored"), 2);
  writeReport(dir_ / "report", r);
  const std::string csv = test::readText(dir_ / "report/label_returns.csv");
  EXPECT_NE(csv.find("0000,0,1,Car,1,"), std::string::npos) << csv;
  EXPECT_NE(csv.find(",5,1\n"), std::string::npos) << csv;
  EXPECT_NE(test::readText(dir_ / "report/report.md").find("--min-points 10"), std::string::npos);
}

TEST_F(MinPoints, GroundTruthWithoutItsScanIsAnErrorNamingTheFrame) {
  EvalData d = makeData(false);
  d.frames[1].velodyne_path.clear();
  try {
    ignoreLabelsWithFewReturns(d, 10);
    FAIL() << "no error";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("sequence 0000 frame 1"), std::string::npos) << e.what();
  }
  EXPECT_THROW(ignoreLabelsWithFewReturns(d, -1), std::invalid_argument);
}

}  // namespace
}  // namespace eval
}  // namespace ret3d
