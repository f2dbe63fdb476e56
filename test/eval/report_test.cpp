#include "ret3d/eval/report.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <sstream>

#include "support/boxes.h"
#include "support/test_util.h"

namespace ret3d {
namespace eval {
namespace {

std::string readAll(const std::string& path) {
  std::ifstream in(path);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

Box car(double x, std::uint32_t id) {
  Box b = test::carBox(x, 0.0);
  b.track_id = id;
  b.num_points = 50;
  return b;
}

TEST(Report, WritesMetricsJsonReportAndPlots) {
  // A small perfect case for every metric family.
  std::vector<EvalFrame> frames(5);
  std::vector<KittiFrame> kframes(5);
  for (int t = 0; t < 5; ++t) {
    frames[t].sequence = "0000";
    frames[t].frame = t;
    frames[t].gt_boxes = {car(10 + t, 1)};
    frames[t].gt_ignore = {0};
    frames[t].pred_boxes = {car(10 + t, 4)};
    kitti::Label l;
    l.type = "Car";
    l.bbox = {100, 150, 200, 250};
    l.h = 1.5;
    l.w = 1.8;
    l.l = 4;
    l.z = 10 + t;
    l.alpha = 0.2;  // the Label default -10 means "no orientation" and switches AOS off
    kframes[t].gt = {l};
    l.score = 0.9;
    kframes[t].det = {l};
  }
  const KittiResult kitti = evaluateKitti(kframes);
  const WaymoResult waymo = evaluateWaymo(frames);
  const MotResult mot = evaluateMot(frames);
  EvalReport r;
  r.gt_source = "unit test ground truth";
  r.pred_source = "unit test predictions";
  r.num_frames = 5;
  r.num_gt = 5;
  r.num_pred = 5;
  r.kitti = &kitti;
  r.kitti_loose = &kitti;
  r.waymo = &waymo;
  r.mot = &mot;
  const IdStabilityResult ids = evaluateIdStability(frames);
  r.id_stability = &ids;

  const auto m = metricsMap(r);
  for (const char* key : {"kitti.Car.3d.R11.easy", "kitti.Car.bev.R40.moderate", "kitti.Pedestrian.2d.R40.hard",
                          "kitti.Cyclist.aos.R11.hard", "kitti_loose.Car.3d.R40.easy", "waymo.Car.L1.AP",
                          "waymo.mean.L2.APH", "waymo.Cyclist.L2.AP", "waymo_range.Car.0-30.L1.AP", "mot.Car.MOTA",
                          "mot.Car.MOTP", "mot.Car.IDSW", "mot.Car.FRAG", "mot.Car.MT", "mot.Car.ML", "mot.Car.HOTA",
                          "mot.Car.DetA", "mot.Car.AssA", "mot.Pedestrian.HOTA"}) {
    EXPECT_TRUE(m.count(key)) << key;
  }
  EXPECT_NEAR(m.at("waymo.Car.L1.APH"), 100.0, 1e-9);
  EXPECT_NEAR(m.at("mot.Car.MOTA"), 100.0, 1e-9);
  EXPECT_NEAR(m.at("mot.Car.MT"), 100.0, 1e-9);  // percent of ground-truth tracks
  EXPECT_NEAR(m.at("mot.Car.IdStability"), 100.0, 1e-9);  // predictions = ground truth: one id per track
  EXPECT_NEAR(m.at("mot.all.IdStability"), 100.0, 1e-9);
  EXPECT_NEAR(m.at("mot.all.IdCoverage"), 100.0, 1e-9);

  test::TempDir dir;
  const auto pngs = writeReport(dir / "report", r);
  const std::string json = readAll(dir / "report/metrics.json");
  EXPECT_NE(json.find("\"kitti.Car.3d.R40.moderate\": "), std::string::npos);
  EXPECT_NE(json.find("\"mot.Car.HOTA\": 100"), std::string::npos) << json;
  EXPECT_EQ(json.front(), '{');
  const std::string md = readAll(dir / "report/report.md");
  for (const char* text : {"## Inputs", "unit test ground truth", "KITTI object detection AP", "Waymo-style",
                           "CLEAR MOT", "| Car |", "Track-id stability", "| all | 100.00 |"}) {
    EXPECT_NE(md.find(text), std::string::npos) << text;
  }
  if (pngs.empty()) GTEST_SKIP() << "gnuplot is not installed: no plots to check";
  EXPECT_EQ(pngs.size(), 3u * 4u + 3u);  // KITTI 2D/BEV/3D/AOS per class, one Waymo plot per class
  const std::string png = readAll(dir / ("report/plots/" + pngs.front()));
  ASSERT_GT(png.size(), 1000u);
  EXPECT_EQ(png.substr(1, 3), "PNG");
}

}  // namespace
}  // namespace eval
}  // namespace ret3d
