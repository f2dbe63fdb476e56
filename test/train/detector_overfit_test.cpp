// The training loop learns: a small network trained on a few hand-made frames (boxes filled with points on a ground
// plane, written as a tiny KITTI tracking dataset) must then find every object of those frames (3D IoU > 0.5) with
// few false positives, for both heads. The same frames moved beyond 48 m, on a grid of x in [-80, 80] m, must be found
// there (the far-field path: grid origin, anchors and box decoding far from the sensor). Also: the dataset reads
// velocities from track ids and ego poses, and a run resumed from its checkpoint continues rather than restarts.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <random>
#include <sstream>

#include <gtest/gtest.h>

#include "ret3d/core/geometry.h"
#include "ret3d/detector/detector.h"
#include "ret3d/io/kitti.h"
#include "ret3d/train/detector_dataset.h"
#include "ret3d/train/detector_trainer.h"
#include "support/test_util.h"

namespace ret3d {
namespace {

constexpr int kFrames = 6;

struct Scene {
  std::vector<std::vector<Box>> boxes;  // per frame, LiDAR frame
  std::vector<PointCloud> clouds;
};

// Points on a ground plane (x from ground_x to ground_x + 32 m) and inside each box (a lattice filling its volume),
// intensity by class.
PointCloud render(const std::vector<Box>& boxes, std::mt19937* rng, float ground_x = 0.0f) {
  PointCloud c;
  std::uniform_real_distribution<float> jitter(-0.04f, 0.04f);
  for (float x = ground_x + 0.1f; x < ground_x + 32.0f; x += 0.35f)
    for (float y = -15.9f; y < 16.0f; y += 0.35f) c.push_back({x + jitter(*rng), y + jitter(*rng), -1.73f, 0.05f});
  for (const Box& b : boxes) {
    const float inten = b.label == ObjectClass::Car ? 0.6f : b.label == ObjectClass::Pedestrian ? 0.3f : 0.9f;
    const double cy = std::cos(b.yaw), sy = std::sin(b.yaw);
    for (double l = -0.5 * b.length + 0.05; l < 0.5 * b.length; l += 0.15)
      for (double w = -0.5 * b.width + 0.05; w < 0.5 * b.width; w += 0.15)
        for (double h = -0.5 * b.height + 0.05; h < 0.5 * b.height; h += 0.2)
          c.push_back({static_cast<float>(b.x + cy * l - sy * w), static_cast<float>(b.y + sy * l + cy * w),
                       static_cast<float>(b.z + h), inten});
  }
  return c;
}

// Five tracked objects moving across six frames, written with the KITTI writers (static ego, identity poses); `dx`
// moves the whole scene along x.
Scene writeDataset(const std::string& root, double dx = 0.0) {
  namespace fs = std::filesystem;
  const std::string tr = root + "/training";
  fs::create_directories(tr + "/velodyne/0000");
  fs::create_directories(tr + "/label_02");
  fs::create_directories(tr + "/calib");
  fs::create_directories(tr + "/pose");
  const kitti::Calibration calib = kitti::defaultCalibration();
  kitti::writeCalibration(tr + "/calib/0000.txt", calib);
  struct Obj {
    ObjectClass c;
    double x, y, yaw, vx, vy, l, w, h;
  };
  const std::vector<Obj> objs = {{ObjectClass::Car, 9, -4, 0.2, 5, 1, 4.0, 1.7, 1.5},
                                 {ObjectClass::Car, 17, 5, -1.4, 0, -6, 4.4, 1.8, 1.6},
                                 {ObjectClass::Pedestrian, 7, 3, 1.0, 0.5, 1.0, 0.7, 0.6, 1.75},
                                 {ObjectClass::Pedestrian, 13, -8, -2.5, -1.0, 0.0, 0.8, 0.6, 1.8},
                                 {ObjectClass::Cyclist, 22, -2, 2.8, -4, 1, 1.8, 0.6, 1.7}};
  Scene scene;
  std::mt19937 rng(11);
  std::vector<kitti::Label> labels;
  std::vector<Eigen::Isometry3d> poses;
  for (int f = 0; f < kFrames; ++f) {
    std::vector<Box> boxes;
    for (std::size_t i = 0; i < objs.size(); ++i) {
      const Obj& o = objs[i];
      Box b;
      b.label = o.c;
      b.x = dx + o.x + o.vx * 0.1 * f, b.y = o.y + o.vy * 0.1 * f;
      b.length = o.l, b.width = o.w, b.height = o.h;
      b.z = -1.73 + 0.5 * o.h;
      b.yaw = o.yaw;
      b.vx = o.vx, b.vy = o.vy;
      b.track_id = static_cast<std::uint32_t>(i + 1);
      boxes.push_back(b);
      kitti::Label l = kitti::boxToLabel(b, calib);
      l.frame = f;
      labels.push_back(l);
    }
    scene.clouds.push_back(render(boxes, &rng, static_cast<float>(dx)));
    char name[64];
    std::snprintf(name, sizeof(name), "/velodyne/0000/%06d.bin", f);
    kitti::writeVelodyne(tr + name, scene.clouds.back());
    scene.boxes.push_back(boxes);
    poses.push_back(Eigen::Isometry3d::Identity());
  }
  kitti::writeTrackingLabels(tr + "/label_02/0000.txt", labels);
  kitti::writePoses(tr + "/pose/0000.txt", poses);
  return scene;
}

DetectorOptions tinyOptions(HeadType head) {
  DetectorOptions o;
  auto& m = o.model;
  m.geometry.x_min = 0, m.geometry.x_max = 32, m.geometry.y_min = -16, m.geometry.y_max = 16;
  m.geometry.resolution = 0.25;  // 128 x 128
  m.network.stem_channels = 16;
  m.network.stage_channels = {24, 32, 48};
  m.network.stage_blocks = {1, 1, 1};
  m.network.attention_heads = 2;
  m.network.decoder_channels = 32;
  m.network.head_channels = 32;
  m.head = head;
  m.anchor.anchors_per_class = 1;
  auto& t = o.train;
  t.epochs = 150;
  t.batch_size = 2;
  t.learning_rate = 4e-3;
  t.warmup_fraction = 0.05;
  t.rotation_range = 0;  // overfitting: the frames as they are (flips keep the task the same)
  t.scale_min = t.scale_max = 1.0;
  t.crop_probability = 0;
  t.block_probability = 0;
  t.checkpoint_minutes = 100;
  o.inference.score_threshold = 0.3f;
  // One thread: on a machine shared with other jobs, two OpenMP threads wait on each other at every small op.
  o.inference.threads = 1;
  return o;
}

// Average precision of one class at 3D IoU > 0.5 with greedy matching by score (all-point interpolation).
double averagePrecision(const std::vector<std::vector<Box>>& dets, const std::vector<std::vector<Box>>& gts,
                        ObjectClass c, int* false_positives) {
  struct Hit {
    float score;
    bool tp;
  };
  std::vector<Hit> hits;
  int n_gt = 0;
  for (std::size_t f = 0; f < gts.size(); ++f) {
    std::vector<Box> d;
    for (const Box& b : dets[f])
      if (b.label == c) d.push_back(b);
    std::sort(d.begin(), d.end(), [](const Box& a, const Box& b) { return a.score > b.score; });
    std::vector<bool> used(gts[f].size(), false);
    for (const Box& g : gts[f]) n_gt += g.label == c;
    for (const Box& b : d) {
      int best = -1;
      double best_iou = 0.5;
      for (std::size_t g = 0; g < gts[f].size(); ++g) {
        if (used[g] || gts[f][g].label != c) continue;
        const double iou = iou3d(b, gts[f][g]);
        if (iou > best_iou) best_iou = iou, best = static_cast<int>(g);
      }
      if (best >= 0) used[best] = true;
      hits.push_back({b.score, best >= 0});
    }
  }
  std::sort(hits.begin(), hits.end(), [](const Hit& a, const Hit& b) { return a.score > b.score; });
  std::vector<double> prec, rec;
  int tp = 0, fp = 0;
  for (const Hit& h : hits) {
    h.tp ? ++tp : ++fp;
    prec.push_back(static_cast<double>(tp) / (tp + fp));
    rec.push_back(static_cast<double>(tp) / std::max(1, n_gt));
  }
  *false_positives = fp;
  double ap = 0, prev_r = 0;
  for (std::size_t i = 0; i < prec.size(); ++i) {
    const double p = *std::max_element(prec.begin() + i, prec.end());
    ap += (rec[i] - prev_r) * p;
    prev_r = rec[i];
  }
  return ap;
}

class DetectorOverfitTest : public ::testing::TestWithParam<HeadType> {};

TEST_P(DetectorOverfitTest, ReachesNearPerfectAPOnItsTrainingFrames) {
  test::TempDir dir;
  const Scene scene = writeDataset(dir.path());
  DetectorTrainJob job;
  job.data_dirs = {dir.path()};
  // These labels cover all around; every object merely happens to stand in camera 2's view, which --labels-cover auto
  // would take for a camera-only (real KITTI) set.
  job.label_cover = {LabelCover::All};
  job.out_model = dir / "tiny.ret3d";
  job.options = tinyOptions(GetParam());
  // The centre head's sparse positives (one cell per object) need longer than the anchor head's three per anchor.
  if (GetParam() == HeadType::Center) job.options.train.epochs = 240;
  job.config_text = "# overfit test\n";
  job.progress = false;
  const DetectorTrainResult r = trainDetector(job);
  std::printf("%s head: %d steps in %.1f s, last epoch loss %.3f\n", headTypeName(GetParam()), r.steps, r.seconds,
              r.last_loss);
  EXPECT_EQ(r.steps, job.options.train.epochs * 3);  // 6 frames, batches of 2

  DetectorOptions o = job.options;
  o.inference.model_path = job.out_model;
  // This scene's ground runs under the sensor, where a real one sees none (its lowest beam meets the ground 3.7 m
  // away): the ego box would crop returns the network was trained on.
  o.inference.ego_box.reset();
  Detector detector(o);
  std::vector<std::vector<Box>> dets;
  std::vector<double> vel_err;
  for (int f = 0; f < kFrames; ++f) {
    const PointCloud* prev = f > 0 ? &scene.clouds[f - 1] : nullptr;
    const Detections d = detector.detect(scene.clouds[f], prev, Eigen::Isometry3d::Identity());
    EXPECT_EQ(d.feature_dim, 32u);
    dets.push_back(d.boxes);
    if (f == 0) continue;
    for (const Box& g : scene.boxes[f])
      for (const Box& b : d.boxes)
        if (b.label == g.label && iou3d(b, g) > 0.5) {
          vel_err.push_back(std::hypot(b.vx - g.vx, b.vy - g.vy));
          break;
        }
  }
  // What must hold on any CPU and BLAS: every object is found where it is (its class within 0.3 m of its centre),
  // the boxes overlap their objects well enough for AP at 3D IoU 0.5 to stay high, and few boxes are false.
  // The floating-point order of the kernels (OpenBLAS and ATen pick them by CPU: AVX2, AVX-512, ...) changes the
  // training trajectory. With the kernels forced to another CPU's (OPENBLAS_CORETYPE=Haswell or Zen with
  // ATEN_CPU_CAPABILITY=avx2, i.e. an AVX2 machine without AVX-512) one cyclist frame of six fell just below
  // 3D IoU 0.5 for both heads (Cyclist AP 0.833 / 0.806), while AVX-512 reached 1.0: six instances give AP steps of
  // 1/6, so a per-class AP bar of 0.9 allowed no miss at all. Per class the bar is 0.75 (one tight box of six may
  // fall below IoU 0.5); over all thirty objects AP at 3D IoU 0.5 must reach 0.9; and the centre-distance recall
  // asserts that no object is missed.
  std::vector<std::vector<Box>> all_dets = dets, all_gts = scene.boxes;
  for (auto* frames : {&all_dets, &all_gts})
    for (auto& frame : *frames)
      for (Box& b : frame) b.label = ObjectClass::Car;  // one pool: AP over every object
  int pooled_fp = 0;
  const double pooled_ap = averagePrecision(all_dets, all_gts, ObjectClass::Car, &pooled_fp);
  std::printf("  all objects AP(3D IoU 0.5) %.3f\n", pooled_ap);
  EXPECT_GE(pooled_ap, 0.9);
  for (ObjectClass c : kDetectedClasses) {
    int fp = 0;
    const double ap = averagePrecision(dets, scene.boxes, c, &fp);
    int found = 0, total = 0;
    for (int f = 0; f < kFrames; ++f)
      for (const Box& g : scene.boxes[f]) {
        if (g.label != c) continue;
        ++total;
        for (const Box& b : dets[f])
          if (b.label == c && iou3d(b, g) >= 0.25) {
            ++found;
            break;
          }
      }
    std::printf("  %s AP(3D IoU 0.5) %.3f, false positives %d, found %d of %d (3D IoU >= 0.25)\n", className(c), ap, fp,
                found, total);
    EXPECT_EQ(found, total) << className(c);
    EXPECT_GE(ap, 0.75) << className(c);
    EXPECT_LE(fp, 3) << className(c);
  }
  ASSERT_FALSE(vel_err.empty());
  std::sort(vel_err.begin(), vel_err.end());
  std::printf("  median velocity error %.2f m/s over %zu matches\n", vel_err[vel_err.size() / 2], vel_err.size());
  EXPECT_LT(vel_err[vel_err.size() / 2], 1.5);
}

INSTANTIATE_TEST_SUITE_P(BothHeads, DetectorOverfitTest, ::testing::Values(HeadType::Center, HeadType::Anchor),
                         [](const auto& info) { return std::string(headTypeName(info.param)); });

// The far-field path: the scene of the overfit test moved 48 m out (objects at x 55-72 m), on a grid like the
// long-range one (x in [-80, 80] m; y narrowed to [-16, 16] m and 0.5 m cells to keep the test small). Every object
// must come out where it is: a box of its class with its centre within 1.25 m (2.5 cells: a wrong grid origin or
// anchor offset moves boxes by metres), and for 27 of the 30 also 3D IoU >= 0.25 (sizes and headings decoded; a
// pedestrian is about one cell wide, and which one or two fall short of 0.25 varies with the CPU's kernels); no box
// this side of 48 m.
TEST(DetectorFarField, BoxesBeyond48mComeOutWhereTheObjectsAre) {
  test::TempDir dir;
  const double dx = 48.0;
  const Scene scene = writeDataset(dir.path(), dx);
  DetectorTrainJob job;
  job.data_dirs = {dir.path()};
  job.label_cover = {LabelCover::All};
  job.out_model = dir / "far.ret3d";
  job.options = tinyOptions(HeadType::Anchor);
  auto& g = job.options.model.geometry;
  g.x_min = -80, g.x_max = 80, g.y_min = -16, g.y_max = 16;
  g.resolution = 0.5;  // 320 x 64 cells
  job.config_text = "# far-field test\n";
  job.progress = false;
  const DetectorTrainResult r = trainDetector(job);
  std::printf("far field: %d steps in %.1f s, last epoch loss %.3f\n", r.steps, r.seconds, r.last_loss);

  DetectorOptions o = job.options;
  o.inference.model_path = job.out_model;
  Detector detector(o);
  int placed = 0, overlapping = 0, total = 0, near_boxes = 0;
  for (int f = 0; f < kFrames; ++f) {
    const PointCloud* prev = f > 0 ? &scene.clouds[f - 1] : nullptr;
    const Detections d = detector.detect(scene.clouds[f], prev, Eigen::Isometry3d::Identity());
    for (const Box& b : d.boxes) near_boxes += b.x < dx;
    for (const Box& gt : scene.boxes[f]) {
      ++total;
      double best_iou = -1;  // of the boxes of its class placed near it
      for (const Box& b : d.boxes) {
        if (b.label != gt.label || std::hypot(b.x - gt.x, b.y - gt.y) >= 1.25) continue;
        best_iou = std::max(best_iou, iou3d(b, gt));
      }
      placed += best_iou >= 0;
      overlapping += best_iou >= 0.25;
      if (best_iou >= 0.25) continue;
      std::ostringstream boxes;
      for (const Box& b : d.boxes) {
        boxes << "\n  " << className(b.label) << " x " << b.x << " y " << b.y << " score " << b.score << " IoU "
              << iou3d(b, gt);
      }
      std::printf("frame %d: %s at x %.2f y %.2f: %s; the boxes:%s\n", f, className(gt.label), gt.x, gt.y,
                  best_iou < 0 ? "no box of its class within 1.25 m" : "3D IoU below 0.25", boxes.str().c_str());
    }
  }
  std::printf("  %d of %d objects beyond %.0f m placed, %d with 3D IoU >= 0.25; %d boxes nearer\n", placed, total, dx,
              overlapping, near_boxes);
  EXPECT_EQ(placed, total);
  EXPECT_GE(overlapping, total - 3);
  EXPECT_EQ(near_boxes, 0);

  // The two-resolution detector (inference.far_field): this model as the far field of a near model of finer cells
  // whose grid lies over part of the scene (x 56-72 m; an untrained network, so its boxes there are noise). Outside
  // the near field shrunk by the margin every box of the far model comes out as its own, with its feature row; inside
  // it none does.
  DetectorOptions two = tinyOptions(HeadType::Anchor);
  two.inference.grid_extent = GridExtent{56, 72, -16, 16};
  two.inference.far_field = FarFieldOptions{std::filesystem::absolute(job.out_model).string(), 2.0};
  Detector both(two);
  ASSERT_TRUE(both.hasFarField());
  DetectorOptions near_only = two;
  near_only.inference.far_field.reset();
  EXPECT_EQ(both.parameterCount(), Detector(near_only).parameterCount() + detector.parameterCount());
  auto owned = [](const Box& b) { return b.x >= 58 && b.x < 70 && b.y >= -14 && b.y < 14; };
  auto same = [](const Box& a, const Box& b) {
    return a.label == b.label && std::abs(a.x - b.x) < 1e-4 && std::abs(a.y - b.y) < 1e-4 &&
           std::abs(a.yaw - b.yaw) < 1e-4 && std::abs(a.score - b.score) < 1e-5;
  };
  int far_kept = 0, far_dropped = 0;
  for (int f = 0; f < kFrames; ++f) {
    const PointCloud* prev = f > 0 ? &scene.clouds[f - 1] : nullptr;
    const Detections alone = detector.detect(scene.clouds[f], prev, Eigen::Isometry3d::Identity());
    const Detections d = both.detect(scene.clouds[f], prev, Eigen::Isometry3d::Identity());
    ASSERT_EQ(d.feature_dim, alone.feature_dim);
    ASSERT_EQ(d.features.size(), d.boxes.size() * d.feature_dim);
    for (std::size_t k = 1; k < d.boxes.size(); ++k) EXPECT_GE(d.boxes[k - 1].score, d.boxes[k].score);
    for (std::size_t i = 0; i < alone.boxes.size(); ++i) {
      const Box& a = alone.boxes[i];
      const auto match = std::find_if(d.boxes.begin(), d.boxes.end(), [&](const Box& b) { return same(b, a); });
      if (owned(a)) {
        ++far_dropped;
        EXPECT_EQ(match, d.boxes.end()) << "frame " << f << ": a far box inside the near field at x " << a.x;
        continue;
      }
      ++far_kept;
      ASSERT_NE(match, d.boxes.end()) << "frame " << f << ": the far box at x " << a.x << " y " << a.y << " is missing";
      const std::size_t k = static_cast<std::size_t>(match - d.boxes.begin());
      for (std::size_t j = 0; j < d.feature_dim; ++j)
        ASSERT_FLOAT_EQ(d.features[k * d.feature_dim + j], alone.features[i * alone.feature_dim + j]);
    }
  }
  std::printf("  two resolutions: %d far boxes kept outside the near field, %d inside it left to the near model\n",
              far_kept, far_dropped);
  EXPECT_GT(far_kept, 0);
  EXPECT_GT(far_dropped, 0);

  DetectorOptions missing = two;
  missing.inference.far_field->model_path = dir / "none.ret3d";
  try {
    Detector bad(missing);
    ADD_FAILURE() << "a missing far-field model was accepted";
  } catch (const std::exception& e) {
    EXPECT_NE(std::string(e.what()).find("none.ret3d"), std::string::npos) << e.what();
  }
}

TEST(DetectorDataset, VelocitiesFromTrackIdsAndEgoMotion) {
  test::TempDir dir;
  const Scene scene = writeDataset(dir.path());
  const DetectorOptions o = tinyOptions(HeadType::Center);
  DetectorDataset data(dir.path(), o.model);
  ASSERT_EQ(data.size(), static_cast<std::size_t>(kFrames));
  EXPECT_EQ(data.allBoxes().size(), 5u * kFrames);
  const DetectorSample first = data.load(0), third = data.load(2);
  EXPECT_FALSE(first.has_previous);
  EXPECT_TRUE(third.has_previous);
  EXPECT_EQ(third.previous.size(), scene.clouds[1].size());
  ASSERT_EQ(third.boxes.size(), 5u);
  for (std::size_t i = 0; i < 5; ++i) {
    const Box& g = scene.boxes[2][i];
    const Box& b = third.boxes[i];
    EXPECT_NEAR(b.x, g.x, 0.02);
    EXPECT_NEAR(b.y, g.y, 0.02);
    EXPECT_NEAR(b.vx, g.vx, 0.3) << i;  // label rounding (centimetres over 0.1 s)
    EXPECT_NEAR(b.vy, g.vy, 0.3) << i;
    EXPECT_TRUE(third.velocity_valid[i]);
    // Frame 0 has no previous frame: the velocity comes from the next one.
    EXPECT_NEAR(first.boxes[i].vx, g.vx, 0.3);
  }
}

TEST(DetectorDataset, AugmentationMovesPointsAndBoxesTogether) {
  test::TempDir dir;
  const Scene scene = writeDataset(dir.path());
  DetectorOptions o = tinyOptions(HeadType::Center);
  DetectorDataset data(dir.path(), o.model);
  DetectorSample s = data.load(3);
  const DetectorSample orig = s;
  o.train.rotation_range = 1.0;
  o.train.scale_min = 0.9, o.train.scale_max = 1.1;
  o.train.flip = true;
  std::mt19937 rng(4);
  augmentSample(&s, o.train, o.model.geometry, &rng);
  // Every object keeps the points that were inside it (boxes lifted off the ground plane, whose points lie on
  // their bottom faces, so boundary rounding does not count).
  auto lifted = [](std::vector<Box> boxes) {
    for (Box& b : boxes) b.z += 0.1, b.height -= 0.2;
    return boxes;
  };
  const auto before = countPointsInBoxes(lifted(orig.boxes), orig.current);
  const auto after = countPointsInBoxes(lifted(s.boxes), s.current);
  ASSERT_EQ(before.size(), after.size());
  for (std::size_t i = 0; i < before.size(); ++i) EXPECT_NEAR(after[i], before[i], 0.02 * before[i] + 2) << i;
  // Multi-scale grid: 32 (12 + n) cells.
  o.train.multiscale_base = 12, o.train.multiscale_n_min = -2, o.train.multiscale_n_max = 0;
  for (int i = 0; i < 10; ++i) {
    const BevGeometry g = multiscaleGeometry(o.model.geometry, o.train, &rng);
    EXPECT_TRUE(g.width() == 320 || g.width() == 352 || g.width() == 384) << g.width();
    EXPECT_EQ(g.width(), g.height());
  }
}

}  // namespace
}  // namespace ret3d
