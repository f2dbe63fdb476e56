#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <random>

#include "ret3d/core/geometry.h"
#include "ret3d/io/kitti.h"
#include "support/test_util.h"

namespace ret3d {
namespace {

namespace fs = std::filesystem;

double angleDiff(double a, double b) { return std::fabs(wrapAngle(a - b)); }

// Label -> box -> label must give back the geometry within 1e-4; returns the largest error.
double roundTripError(const kitti::Label& l, const kitti::Calibration& calib) {
  const Box b = kitti::labelToBox(l, calib);
  const kitti::Label r = kitti::boxToLabel(b, calib);
  double err = 0;
  for (double d : {r.h - l.h, r.w - l.w, r.l - l.l, r.x - l.x, r.y - l.y, r.z - l.z}) err = std::max(err, std::fabs(d));
  return std::max(err, angleDiff(r.rotation_y, l.rotation_y));
}

// The canonical KITTI mounting without the small calibration angles: camera x = -LiDAR y, y = -LiDAR z, z = LiDAR x.
kitti::Calibration axisAlignedCalibration() {
  kitti::Calibration c = kitti::defaultCalibration();
  c.R0_rect.setIdentity();
  c.velo_to_cam.linear() << 0, -1, 0, 0, 0, -1, 1, 0, 0;
  c.velo_to_cam.translation().setZero();
  return c;
}

kitti::Label carAt(double x, double y, double z, double ry) {
  kitti::Label l;
  l.type = "Car";
  l.h = 1.5;
  l.w = 1.6;
  l.l = 4.0;
  l.x = x;
  l.y = y;
  l.z = z;
  l.rotation_y = ry;
  return l;
}

TEST(LabelBox, AxisAlignedGeometryIsTheKittiConvention) {
  const kitti::Calibration c = axisAlignedCalibration();
  // Bottom centre 1.5 m below the camera, 10 m ahead, 2 m to the right.
  const Box b = kitti::labelToBox(carAt(2.0, 1.5, 10.0, -M_PI / 2), c);
  EXPECT_NEAR(b.x, 10.0, 1e-12);
  EXPECT_NEAR(b.y, -2.0, 1e-12);
  EXPECT_NEAR(b.z, -0.75, 1e-12);  // geometric centre: half the height above the bottom
  EXPECT_DOUBLE_EQ(b.length, 4.0);
  EXPECT_DOUBLE_EQ(b.width, 1.6);
  EXPECT_DOUBLE_EQ(b.height, 1.5);
  EXPECT_EQ(b.label, ObjectClass::Car);
  // rotation_y = -pi/2 faces along camera z (away from us) = LiDAR +x: yaw = -rotation_y - pi/2.
  EXPECT_NEAR(b.yaw, 0.0, 1e-12);
  EXPECT_NEAR(kitti::labelToBox(carAt(2, 1.5, 10, 0.0), c).yaw, -M_PI / 2, 1e-12);  // facing camera x = LiDAR -y
  EXPECT_NEAR(kitti::labelToBox(carAt(2, 1.5, 10, M_PI / 2), c).yaw, M_PI, 1e-12);  // facing us
  EXPECT_NEAR(kitti::labelToBox(carAt(2, 1.5, 10, -M_PI), c).yaw, M_PI / 2, 1e-12);  // facing camera -x = LiDAR +y
  // And back: alpha of an object straight ahead equals rotation_y; to the right it is rotation_y - atan2(x, z).
  const kitti::Label l = kitti::boxToLabel(b, c);
  EXPECT_NEAR(l.rotation_y, -M_PI / 2, 1e-12);
  EXPECT_NEAR(l.alpha, -M_PI / 2 - std::atan2(2.0, 10.0), 1e-12);
  EXPECT_NEAR(l.y, 1.5, 1e-12);
}

TEST(LabelBox, TrackIdClassAndScoreMapping) {
  const kitti::Calibration c = kitti::defaultCalibration();
  kitti::Label l = carAt(1, 1.6, 20, 0.3);
  l.track_id = 0;  // KITTI ids start at 0 ...
  EXPECT_EQ(kitti::labelToBox(l, c).track_id, 1u);  // ... ours at 1 (0 = none)
  EXPECT_EQ(kitti::boxToLabel(kitti::labelToBox(l, c), c).track_id, 0);
  l.track_id = 41;
  EXPECT_EQ(kitti::labelToBox(l, c).track_id, 42u);
  l.track_id = -1;
  EXPECT_EQ(kitti::labelToBox(l, c).track_id, 0u);
  Box b = kitti::labelToBox(l, c);
  EXPECT_EQ(kitti::boxToLabel(b, c).track_id, -1);
  EXPECT_FLOAT_EQ(b.score, 1.0f);  // no score in the label: the Box default
  l.score = 0.25;
  EXPECT_FLOAT_EQ(kitti::labelToBox(l, c).score, 0.25f);
  ASSERT_TRUE(kitti::boxToLabel(kitti::labelToBox(l, c), c).score);
  EXPECT_DOUBLE_EQ(*kitti::boxToLabel(kitti::labelToBox(l, c), c).score, 0.25);

  for (const char* t : {"Pedestrian", "Cyclist"}) {
    l.type = t;
    b = kitti::labelToBox(l, c);
    EXPECT_EQ(std::string(className(b.label)), t);
    EXPECT_EQ(kitti::boxToLabel(b, c).type, t);
  }
  for (const char* t : {"Van", "Person_sitting", "Truck", "Misc", "DontCare"}) {
    l.type = t;
    EXPECT_EQ(kitti::labelToBox(l, c).label, ObjectClass::Unknown) << t;
  }
  EXPECT_EQ(kitti::boxToLabel(kitti::labelToBox(l, c), c).type, "Misc");
}

TEST(LabelBox, SyntheticLabelsRoundTripExactly) {
  std::mt19937 rng(42);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  // The real calibration, and random perturbations of it (other mountings).
  std::vector<kitti::Calibration> calibs = {kitti::defaultCalibration(), axisAlignedCalibration()};
  for (int k = 0; k < 8; ++k) {
    kitti::Calibration c = kitti::defaultCalibration();
    const Eigen::Matrix3d tilt = (Eigen::AngleAxisd(0.2 * (u(rng) - 0.5), Eigen::Vector3d::UnitX()) *
                                  Eigen::AngleAxisd(0.2 * (u(rng) - 0.5), Eigen::Vector3d::UnitY()) *
                                  Eigen::AngleAxisd(0.2 * (u(rng) - 0.5), Eigen::Vector3d::UnitZ()))
                                     .toRotationMatrix();
    c.velo_to_cam.linear() = tilt * c.velo_to_cam.linear();
    c.velo_to_cam.translation() += Eigen::Vector3d(u(rng) - 0.5, u(rng) - 0.5, u(rng) - 0.5);
    calibs.push_back(c);
  }
  double worst = 0;
  for (const auto& c : calibs) {
    for (int i = 0; i < 2000; ++i) {
      kitti::Label l = carAt(-30 + 60 * u(rng), -1 + 4 * u(rng), 1 + 80 * u(rng), -M_PI + 2 * M_PI * u(rng));
      l.h = 0.5 + 3 * u(rng);
      l.w = 0.4 + 2.5 * u(rng);
      l.l = 0.4 + 15 * u(rng);
      if (i == 0) l.rotation_y = M_PI;  // the boundary of (-pi, pi]
      worst = std::max(worst, roundTripError(l, c));
    }
  }
  EXPECT_LT(worst, 1e-9);
}

struct RealLabel {
  kitti::Label label;
  std::string calib;
};

std::vector<RealLabel> realLabels(const std::string& data) {
  std::vector<RealLabel> out;
  const std::string track = data + "/kitti_tracking/training";
  for (const auto& e : fs::directory_iterator(track + "/label_02")) {
    const std::string calib = track + "/calib/" + e.path().filename().string();
    for (const auto& l : kitti::readTrackingLabels(e.path().string())) out.push_back({l, calib});
  }
  const std::string obj = data + "/kitti_object/training";
  for (const auto& e : fs::directory_iterator(obj + "/label_2")) {
    const std::string calib = obj + "/calib/" + e.path().filename().string();
    for (const auto& l : kitti::readObjectLabels(e.path().string())) out.push_back({l, calib});
  }
  return out;
}

TEST(LabelBox, EveryRealLabelRoundTripsWithin1e4) {
  const auto data = test::sharedDataDir();
  if (!data) GTEST_SKIP() << test::kSharedDataMissing;
  std::map<std::string, kitti::Calibration> calibs;
  std::size_t n = 0;
  double worst = 0;
  for (const auto& [l, calib_path] : realLabels(*data)) {
    if (l.type == "DontCare") continue;
    if (!calibs.count(calib_path)) calibs[calib_path] = kitti::readCalibration(calib_path);
    const kitti::Calibration& c = calibs[calib_path];
    const double err = roundTripError(l, c);
    ASSERT_LT(err, 1e-4) << calib_path << " frame " << l.frame << " " << kitti::formatTrackingLabel(l);
    worst = std::max(worst, err);
    const Box b = kitti::labelToBox(l, c);
    EXPECT_EQ(kitti::boxToLabel(b, c).track_id, l.track_id);
    ++n;
  }
  // All but the DontCare regions: the tracking labels' known count, and every object label line of the folder.
  std::size_t object_labels = 0;
  for (const auto& e : fs::directory_iterator(*data + "/kitti_object/training/label_2")) {
    std::ifstream in(e.path());
    for (std::string line; std::getline(in, line);)
      object_labels += !line.empty() && line.rfind("DontCare", 0) != 0;
  }
  EXPECT_GE(object_labels, 38u);  // the six labelled frames' 46 lines, 8 of them DontCare
  EXPECT_EQ(n, 64212u - 17661u + object_labels);
  RecordProperty("worst_error", std::to_string(worst));
}

TEST(LabelBox, AlphaAndImageBoxAgreeWithRealLabels) {
  const auto data = test::sharedDataDir();
  if (!data) GTEST_SKIP() << test::kSharedDataMissing;
  std::map<std::string, kitti::Calibration> calibs;
  std::vector<double> alpha_err, iou;
  for (const auto& [l, calib_path] : realLabels(*data)) {
    if (l.type == "DontCare" || l.z < 2.0) continue;  // objects beside/behind the camera were annotated differently
    if (!calibs.count(calib_path)) calibs[calib_path] = kitti::readCalibration(calib_path);
    const kitti::Label r = kitti::boxToLabel(kitti::labelToBox(l, calibs[calib_path]), calibs[calib_path]);
    alpha_err.push_back(angleDiff(r.alpha, l.alpha));
    if (l.truncated == 0 && l.occluded == 0) iou.push_back(iou2d(r.bbox, l.bbox));
  }
  ASSERT_GT(alpha_err.size(), 40000u);
  std::sort(alpha_err.begin(), alpha_err.end());
  std::sort(iou.begin(), iou.end());
  const double alpha_median = alpha_err[alpha_err.size() / 2];
  const double alpha_p99 = alpha_err[alpha_err.size() * 99 / 100];
  const double iou_median = iou[iou.size() / 2];
  const double iou_p10 = iou[iou.size() / 10];
  std::printf("alpha |error|: median %.4f, p99 %.4f rad; 2D box IoU (unoccluded, untruncated, n=%zu): median %.3f, "
              "p10 %.3f\n", alpha_median, alpha_p99, iou.size(), iou_median, iou_p10);
  // Labels carry 2 (object) or 6 (tracking) decimals; the annotations' own alpha was computed the same way.
  EXPECT_LT(alpha_median, 0.01);
  EXPECT_LT(alpha_p99, 0.06);
  // The 2D boxes were drawn in the image, the 3D boxes fitted to the LiDAR: they agree closely, not exactly.
  EXPECT_GT(iou_median, 0.8);
  EXPECT_GT(iou_p10, 0.6);
}

TEST(LabelBox, ImageBoxIsClippedAndEmptyBehindTheCamera) {
  const kitti::Calibration c = kitti::defaultCalibration();
  Box b;
  b.length = 4;
  b.width = 1.8;
  b.height = 1.5;
  b.x = 15;
  b.y = 0;
  b.z = -0.9;
  kitti::Label l = kitti::boxToLabel(b, c);
  EXPECT_GT(l.bbox[0], 500);  // a car straight ahead projects around the principal point
  EXPECT_LT(l.bbox[2], 720);
  EXPECT_LT(l.bbox[0], l.bbox[2]);
  EXPECT_LT(l.bbox[1], l.bbox[3]);
  b.y = 4;  // to the left and close: partly outside the image
  b.x = 5;
  l = kitti::boxToLabel(b, c);
  EXPECT_DOUBLE_EQ(l.bbox[0], 0.0);
  EXPECT_GT(l.bbox[2], 0.0);
  const kitti::Label unclipped = kitti::boxToLabel(b, c, std::nullopt);
  EXPECT_LT(unclipped.bbox[0], 0.0);
  b.x = -10;  // behind the camera
  b.y = 0;
  l = kitti::boxToLabel(b, c);
  EXPECT_EQ(l.bbox, (std::array<double, 4>{{0, 0, 0, 0}}));
  b.x = 0.5;  // straddling the camera plane: the visible part still gets a box
  b.y = 0;
  l = kitti::boxToLabel(b, c, std::nullopt);
  EXPECT_LT(l.bbox[0], l.bbox[2]);
}

// The rule: every labelled Car within 40 m of the six labelled KITTI object frames has at least
// kMinCarReturns returns inside its labelled box grown by 0.25 m on each side in length and width (height unchanged).
// The margin absorbs label offsets such as 000134's car at 34.7 m, whose visible side lies 0.15 m outside its box
// (3 returns strictly inside). No frame or car is exempted.
TEST(LabelBox, LabelledCarsContainLidarPoints) {
  const auto data = test::sharedDataDir();
  if (!data) GTEST_SKIP() << test::kSharedDataMissing;
  const kitti::ObjectDataset ds(*data + "/kitti_object");
  constexpr double kMargin = 0.25;
  constexpr std::uint32_t kMinCarReturns = 10;
  int cars = 0;
  for (const std::string& f : test::kLabelledObjectFrames) {
    ASSERT_TRUE(fs::exists(ds.labelPath(f)) && fs::exists(ds.velodynePath(f)) && fs::exists(ds.calibPath(f)))
        << "frame " << f << " is missing from " << ds.dir();
    const kitti::Calibration calib = kitti::readCalibration(ds.calibPath(f));
    const PointCloud cloud = kitti::readVelodyne(ds.velodynePath(f));
    std::vector<Box> labelled, grown;
    std::vector<int> line;  // the car's line in the label file, to name it
    const auto labels = kitti::readObjectLabels(ds.labelPath(f));
    for (std::size_t i = 0; i < labels.size(); ++i) {
      if (labels[i].type != "Car") continue;
      Box b = kitti::labelToBox(labels[i], calib);
      if (std::hypot(b.x, b.y) > 40.0) continue;
      labelled.push_back(b);
      b.length += 2 * kMargin;
      b.width += 2 * kMargin;
      grown.push_back(b);
      line.push_back(static_cast<int>(i) + 1);
    }
    const auto counts = countPointsInBoxes(grown, cloud);
    const auto strict = countPointsInBoxes(labelled, cloud);  // reported only
    std::uint32_t smallest = 0;
    for (std::size_t i = 0; i < grown.size(); ++i) {
      const std::string what = "frame " + f + " car on label line " + std::to_string(line[i]) + " at (" +
                               std::to_string(grown[i].x) + ", " + std::to_string(grown[i].y) + ")";
      std::printf("%s: %u returns within %.2f m (%u inside the label)\n", what.c_str(), counts[i], kMargin, strict[i]);
      EXPECT_GE(counts[i], kMinCarReturns) << what;
      EXPECT_EQ(counts[i], countPointsInBox(grown[i], cloud)) << what;
      smallest = i == 0 ? counts[i] : std::min(smallest, counts[i]);
      ++cars;
    }
    if (grown.empty()) {
      std::printf("frame %s: no car within 40 m\n", f.c_str());
    } else {
      std::printf("frame %s: %zu cars within 40 m, smallest count %u\n", f.c_str(), grown.size(), smallest);
    }
  }
  // 000002: 1, 000134: 3, 001545: 6 (000000, 000001 and 000076 have none within 40 m).
  EXPECT_EQ(cars, 10);
}

}  // namespace
}  // namespace ret3d
