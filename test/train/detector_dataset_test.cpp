// Training data beyond the simulator's tracking folders: KITTI object-layout folders (one sweep, no velocity), the
// labelled field of view of real labels (camera 2 only: no loss outside it), DontCare regions and KITTI's other
// classes (ignored, never positives), and several sets mixed by weight per epoch.
#include <algorithm>
#include <cmath>
#include <filesystem>
#include <iostream>
#include <numeric>
#include <random>

#include <gtest/gtest.h>

#include "ret3d/detector/nn/heads.h"
#include "ret3d/io/kitti.h"
#include "ret3d/train/detector_dataset.h"
#include "support/error_message.h"
#include "support/test_util.h"

namespace ret3d {
namespace {

namespace fs = std::filesystem;

Box makeBox(ObjectClass c, double x, double y, double yaw, double l, double w, double h) {
  Box b;
  b.label = c;
  b.x = x, b.y = y, b.yaw = yaw, b.length = l, b.width = w, b.height = h;
  b.z = -1.73 + 0.5 * h;
  return b;
}

kitti::Label labelOf(const Box& b, const std::string& type) {
  kitti::Label l = kitti::boxToLabel(b, kitti::defaultCalibration());
  l.type = type;
  l.track_id = -1;
  return l;
}

// KITTI's DontCare line: an image box without a 3D box.
kitti::Label dontCare(const std::array<double, 4>& bbox) {
  kitti::Label l;
  l.type = "DontCare";
  l.truncated = -1, l.occluded = -1, l.alpha = -10;
  l.bbox = bbox;
  l.h = l.w = l.l = -1;
  l.x = l.y = l.z = -1000;
  l.rotation_y = -10;
  return l;
}

// A ground patch, enough for a scan file.
PointCloud groundPatch() {
  PointCloud c;
  for (float x = -10; x < 10; x += 2)
    for (float y = -10; y < 10; y += 2) c.push_back({x, y, -1.73f, 0.1f});
  return c;
}

// ROOT/training/{velodyne,label_2,calib}/STEM.*; labels are not written when `labelled` is false.
void writeObjectFrame(const std::string& root, const std::string& stem, const std::vector<kitti::Label>& labels,
                      bool labelled = true) {
  const std::string tr = root + "/training";
  for (const char* sub : {"/velodyne", "/label_2", "/calib"}) fs::create_directories(tr + sub);
  kitti::writeVelodyne(tr + "/velodyne/" + stem + ".bin", groundPatch());
  kitti::writeCalibration(tr + "/calib/" + stem + ".txt", kitti::defaultCalibration());
  if (labelled) kitti::writeObjectLabels(tr + "/label_2/" + stem + ".txt", labels);
}

// The BEV box a DontCare region stands for (an unlabelled car at 25 m, 4 m right).
const Box kUnlabelled = makeBox(ObjectClass::Car, 25, -4, 0.0, 4.0, 1.7, 1.5);

struct ObjectSet {
  test::TempDir dir;
  std::vector<Box> cars, pedestrians;
  ObjectSet() {
    cars = {makeBox(ObjectClass::Car, 12, 2, 0.3, 4.2, 1.8, 1.5)};
    pedestrians = {makeBox(ObjectClass::Pedestrian, 9, 3.5, 1.2, 0.7, 0.6, 1.8)};
    const Box van = makeBox(ObjectClass::Car, 20, 5, 0.0, 5.0, 2.0, 2.2);
    const Box sitting = makeBox(ObjectClass::Pedestrian, 7, 1, 0.0, 0.8, 0.6, 1.2);
    const std::array<double, 4> dc = kitti::boxToLabel(kUnlabelled, kitti::defaultCalibration()).bbox;
    writeObjectFrame(dir.path(), "000000",
                     {labelOf(cars[0], "Car"), labelOf(pedestrians[0], "Pedestrian"), labelOf(van, "Van"),
                      labelOf(sitting, "Person_sitting"), dontCare(dc)});
    writeObjectFrame(dir.path(), "000001", {labelOf(cars[0], "Car")});
    writeObjectFrame(dir.path(), "000002", {}, false);  // a scan without labels: not training data
  }
};

TEST(DetectorDataset, ReadsTheObjectLayout) {
  ObjectSet set;
  DetectorDataset data(set.dir.path(), ModelConfig());
  ASSERT_EQ(data.size(), 2u);  // 000002 has no labels
  EXPECT_EQ(data.layout(0), "object");
  EXPECT_EQ(data.sources()[0].cover, LabelCover::Camera);  // every label has a 2D box: auto-detected
  const DetectorSample s = data.load(0);
  EXPECT_EQ(s.id, "000000");
  EXPECT_FALSE(s.has_previous);
  EXPECT_TRUE(s.previous.empty());
  EXPECT_EQ(s.current.size(), groundPatch().size());
  ASSERT_EQ(s.boxes.size(), 2u);
  ASSERT_EQ(s.velocity_valid.size(), 2u);
  EXPECT_FALSE(s.velocity_valid[0]);
  EXPECT_FALSE(s.velocity_valid[1]);
  for (const Box& want : {set.cars[0], set.pedestrians[0]}) {
    const auto it = std::find_if(s.boxes.begin(), s.boxes.end(), [&](const Box& b) { return b.label == want.label; });
    ASSERT_NE(it, s.boxes.end());
    EXPECT_NEAR(it->x, want.x, 1e-4);
    EXPECT_NEAR(it->y, want.y, 1e-4);
    EXPECT_NEAR(it->z, want.z, 1e-4);
    EXPECT_NEAR(it->length, want.length, 1e-4);
    EXPECT_NEAR(std::abs(wrapAngle(it->yaw - want.yaw)), 0.0, 1e-4);
  }
  // Van (for Car) and Person_sitting (for Pedestrian) are ignored; DontCare becomes an image region.
  EXPECT_EQ(s.ignore.size(), 2u);
  EXPECT_EQ(s.ignore_regions.size(), 1u);
  ASSERT_TRUE(s.labelled_view.has_value());
}

TEST(DetectorDataset, ExplicitCoverOverridesTheDetection) {
  ObjectSet set;
  DetectorDataset data(std::vector<DetectorDataSource>{{set.dir.path(), 1.0, LabelCover::All}}, ModelConfig());
  EXPECT_EQ(data.sources()[0].cover, LabelCover::All);
  EXPECT_FALSE(data.load(0).labelled_view.has_value());
}

TEST(DetectorDataset, RejectsAFolderOfNeitherLayout) {
  test::TempDir dir;
  fs::create_directories(dir / "training/somethingelse");
  const std::string msg = test::errorMessage([&] { DetectorDataset data(dir.path(), ModelConfig()); });
  EXPECT_NE(msg.find("neither a KITTI tracking layout"), std::string::npos) << msg;
}

nn::GroundTruth truthOf(const DetectorSample& s) {
  nn::GroundTruth gt;
  gt.boxes = s.boxes;
  gt.velocity_valid = s.velocity_valid;
  gt.ignore = s.ignore;
  gt.ignore_regions = s.ignore_regions;
  gt.labelled_view = s.labelled_view;
  return gt;
}

ModelConfig smallConfig(HeadType head) {
  ModelConfig m;
  m.geometry.x_min = -32, m.geometry.x_max = 32, m.geometry.y_min = -32, m.geometry.y_max = 32;
  m.geometry.resolution = 0.5;  // 128 x 128
  m.head = head;
  return m;
}

float maskAt(const torch::Tensor& mask, const BevGeometry& g, int stride, double x, double y) {
  const Eigen::Vector2d f = g.metricToFeature(x, y, stride);
  return mask[static_cast<int>(f.y())][static_cast<int>(f.x())].item<float>();
}

TEST(DetectorDataset, CameraViewMasksCellsOutsideTheLabelledView) {
  ObjectSet set;
  DetectorDataset data(set.dir.path(), ModelConfig());
  const nn::GroundTruth gt = truthOf(data.load(0));
  const BevGeometry g = smallConfig(HeadType::Center).geometry;
  const auto mask = nn::supervisionMask(gt, g, 1, g.height(), g.width());
  EXPECT_EQ(maskAt(mask, g, 1, 20, 6), 1.0f);     // ahead, in view
  EXPECT_EQ(maskAt(mask, g, 1, -15, 0), 0.0f);    // behind the camera
  EXPECT_EQ(maskAt(mask, g, 1, 1, 20), 0.0f);     // beside it, left
  EXPECT_EQ(maskAt(mask, g, 1, 2, -20), 0.0f);    // and right
  EXPECT_EQ(maskAt(mask, g, 1, kUnlabelled.x, kUnlabelled.y), 0.0f);  // behind the DontCare box
  EXPECT_EQ(maskAt(mask, g, 1, 20, 5), 0.0f);     // the Van
  // An all-around set masks none of these.
  nn::GroundTruth all = gt;
  all.labelled_view.reset();
  const auto open = nn::supervisionMask(all, g, 1, g.height(), g.width());
  EXPECT_EQ(maskAt(open, g, 1, -15, 0), 1.0f);
  EXPECT_EQ(maskAt(open, g, 1, 1, 20), 1.0f);
}

TEST(DetectorDataset, TheViewFollowsTheAugmentation) {
  ObjectSet set;
  DetectorDataset data(set.dir.path(), ModelConfig());
  TrainOptions t;
  t.rotation_range = M_PI;
  t.flip = true;
  t.crop_probability = 0, t.block_probability = 0;
  std::mt19937 rng(5);
  for (int k = 0; k < 10; ++k) {
    DetectorSample s = data.load(0);
    augmentSample(&s, t, ModelConfig().geometry, &rng);
    ASSERT_TRUE(s.labelled_view.has_value());
    for (const Box& b : s.boxes) EXPECT_TRUE(s.labelled_view->contains({b.x, b.y})) << k;
    for (const Box& b : s.boxes)
      for (const BevWedge& r : s.ignore_regions) EXPECT_FALSE(r.contains({b.x, b.y})) << k;
  }
}

// The loss itself: a confident prediction behind the camera costs nothing on a camera-view set, one ahead does.
// Random clipping is drawn over the model's grid: on a +-80 m grid a car at 70 m is kept by some clips (a long-range
// model learns far objects), while the +-48 m grid's clips never reach it.
TEST(DetectorDataset, ClippingCoversTheWholeGrid) {
  TrainOptions t;
  t.crop_probability = 1, t.block_probability = 0;
  t.rotation_range = 0, t.flip = false, t.scale_min = t.scale_max = 1;
  Box car;
  car.label = ObjectClass::Car, car.x = 70, car.y = 5, car.z = -0.9, car.length = 4.2, car.width = 1.8, car.height = 1.5;
  auto keptOf = [&](const BevGeometry& grid) {
    std::mt19937 rng(11);
    int kept = 0;
    for (int k = 0; k < 40; ++k) {
      DetectorSample s;
      for (int i = 0; i < 20; ++i) s.current.push_back(Point{70.0f + 0.1f * i, 5.0f, -1.0f, 0.3f});
      s.boxes = {car};
      s.velocity_valid = {true};
      augmentSample(&s, t, grid, &rng);
      if (!s.boxes.empty())
        ++kept;
      else
        EXPECT_EQ(s.ignore.size(), 1u);  // a clipped object is ignored, not taught as background
    }
    return kept;
  };
  BevGeometry wide = ModelConfig().geometry;
  wide.x_min = -80, wide.x_max = 80;
  EXPECT_GT(keptOf(wide), 10);
  EXPECT_EQ(keptOf(ModelConfig().geometry), 0);
}

TEST(DetectorDataset, NoLossOutsideTheCameraViewInEitherHead) {
  ObjectSet set;
  DetectorDataset data(set.dir.path(), ModelConfig());
  for (HeadType head : {HeadType::Anchor, HeadType::Center}) {
    ModelConfig m = smallConfig(head);
    std::vector<Anchor> anchors;
    for (int stride : m.anchor.strides)
      for (ObjectClass c : m.classes) anchors.push_back({c, 4.0, 1.8, 1.6, -1.0, stride});
    const auto h = nn::makeHead(m, anchors);
    nn::GroundTruth gt = truthOf(data.load(0));
    auto lossWithPeakAt = [&](double x, double y, const nn::GroundTruth& truth) {
      nn::NetworkOutput out;
      for (const auto& [stride, channels] : h->outputChannels()) {
        auto raw = torch::full({1, channels, m.geometry.height() / stride, m.geometry.width() / stride}, -6.0);
        if (x != 0 || y != 0) {
          const Eigen::Vector2d f = m.geometry.metricToFeature(x, y, stride);
          raw[0][0][static_cast<int>(f.y())][static_cast<int>(f.x())] = 6.0;  // objectness / first class heat
        }
        out.head[stride] = raw;
      }
      for (const auto& kv : h->loss(out, {truth}, m.geometry, TrainOptions()).parts)
        if (kv.first == "obj" || kv.first == "heat") return kv.second;
      return -1.0;
    };
    const double base = lossWithPeakAt(0, 0, gt);
    EXPECT_NEAR(lossWithPeakAt(-15, 0.3, gt), base, 1e-6) << headTypeName(head);   // behind: masked
    EXPECT_NEAR(lossWithPeakAt(1.3, 20.3, gt), base, 1e-6) << headTypeName(head);  // beside: masked
    EXPECT_GT(lossWithPeakAt(20.3, -10.3, gt), base + 1e-3) << headTypeName(head);  // ahead: a false positive
    gt.labelled_view.reset();
    EXPECT_GT(lossWithPeakAt(-15, 0.3, gt), lossWithPeakAt(0, 0, gt) + 1e-3) << headTypeName(head);
  }
}

TEST(DetectorDataset, WeightsSetHowOftenEachSetIsDrawn) {
  test::TempDir a, b;
  const Box car = makeBox(ObjectClass::Car, 12, 2, 0.3, 4.2, 1.8, 1.5);
  for (int i = 0; i < 4; ++i) writeObjectFrame(a.path(), "00000" + std::to_string(i), {labelOf(car, "Car")});
  for (int i = 0; i < 2; ++i) writeObjectFrame(b.path(), "00000" + std::to_string(i), {labelOf(car, "Car")});
  DetectorDataset data(std::vector<DetectorDataSource>{{a.path(), 1.0}, {b.path(), 3.0}}, ModelConfig());
  ASSERT_EQ(data.size(), 6u);
  EXPECT_EQ(data.setSize(0), 4u);
  EXPECT_EQ(data.setSize(1), 2u);
  for (int epoch = 0; epoch < 3; ++epoch) {
    const auto order = epochOrder(data, 42, epoch);
    ASSERT_EQ(order.size(), 4u + 2u * 3u);
    std::vector<int> seen(data.size(), 0);
    for (std::size_t i : order) ++seen[i];
    for (std::size_t i = 0; i < data.size(); ++i) EXPECT_EQ(seen[i], data.setOf(i) == 1 ? 3 : 1);
    EXPECT_EQ(order, epochOrder(data, 42, epoch));  // a resumed run draws the same epoch
  }
  EXPECT_NE(epochOrder(data, 42, 0), epochOrder(data, 42, 1));

  // Fractional: about w per frame on average, drawn anew each epoch but fixed per (seed, epoch).
  DetectorDataset frac(std::vector<DetectorDataSource>{{a.path(), 0.5}, {b.path(), 2.25}}, ModelConfig());
  double na = 0, nb = 0;
  const int epochs = 400;
  for (int e = 0; e < epochs; ++e) {
    const auto order = epochOrder(frac, 7, e);
    EXPECT_EQ(order, epochOrder(frac, 7, e));
    for (std::size_t i : order) (frac.setOf(i) == 0 ? na : nb) += 1;
  }
  EXPECT_NEAR(na / (4.0 * epochs), 0.5, 0.05);
  EXPECT_NEAR(nb / (2.0 * epochs), 2.25, 0.05);

  // All weights 1: the plain shuffle the trainer always used, so old runs resume unchanged.
  DetectorDataset plain(std::vector<std::string>{a.path(), b.path()}, ModelConfig());
  std::vector<std::size_t> old(plain.size());
  std::iota(old.begin(), old.end(), 0);
  std::mt19937 order_rng(42u * 7919u + 3u);
  std::shuffle(old.begin(), old.end(), order_rng);
  EXPECT_EQ(epochOrder(plain, 42, 3), old);
}

// Real KITTI: the computed camera view holds every labelled Car, Pedestrian and Cyclist (read only, never trained on).
TEST(DetectorDataset, RealKittiObjectsLieInsideTheCameraView) {
  const auto shared = test::sharedDataDir();
  if (!shared || !fs::is_directory(*shared + "/kitti_object/training/label_2")) GTEST_SKIP() << test::kSharedDataMissing;
  DetectorDataset data(*shared + "/kitti_object", ModelConfig());
  EXPECT_EQ(data.sources()[0].cover, LabelCover::Camera);
  int objects = 0;
  double worst = 0;  // how far the farthest object centre lies outside the view
  double in_view = 0, behind_dont_care = 0;  // cells of the default 96 m grid (at 1 m)
  for (std::size_t i = 0; i < data.size(); ++i) {
    const DetectorSample s = data.load(i);
    ASSERT_TRUE(s.labelled_view.has_value());
    BevWedge tight = *s.labelled_view;
    tight.margin = 0;
    for (const Box& b : s.boxes) {
      ++objects;
      EXPECT_TRUE(s.labelled_view->contains({b.x, b.y})) << s.id << " " << className(b.label) << " at " << b.x
                                                            << ", " << b.y;
      double m = 0;
      while (m < 20 && !BevWedge{tight.apex, tight.ray_a, tight.ray_b, m}.contains({b.x, b.y})) m += 0.05;
      worst = std::max(worst, m);
    }
    for (double x = -47.5; x < 48; x += 1)
      for (double y = -47.5; y < 48; y += 1) {
        if (!s.labelled_view->contains({x, y})) continue;
        ++in_view;
        for (const BevWedge& r : s.ignore_regions)
          if (r.contains({x, y})) {
            ++behind_dont_care;
            break;
          }
      }
  }
  EXPECT_GT(objects, 20);
  std::cout << objects << " labelled objects; the farthest centre lies " << worst
            << " m outside the camera view; DontCare regions mask " << 100 * behind_dont_care / in_view
            << " % of the view's cells" << std::endl;
}

}  // namespace
}  // namespace ret3d
