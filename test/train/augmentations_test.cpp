// The sim-to-real augmentations (train/augmentations.h): each does what its option says, keeps points and boxes
// together, never pastes an object onto another, and changes nothing (nor draws a random number) while off.
#include "ret3d/train/augmentations.h"

#include <cmath>
#include <cstring>
#include <fstream>
#include <set>
#include <tuple>

#include <gtest/gtest.h>

#include "ret3d/core/geometry.h"
#include "ret3d/core/transform.h"
#include "support/test_util.h"

namespace ret3d {
namespace {

Box makeBox(ObjectClass c, double x, double y, double yaw) {
  Box b;
  b.label = c;
  b.x = x, b.y = y, b.yaw = yaw;
  if (c == ObjectClass::Car) b.length = 4.2, b.width = 1.8, b.height = 1.6;
  if (c == ObjectClass::Pedestrian) b.length = 0.8, b.width = 0.7, b.height = 1.75;
  if (c == ObjectClass::Cyclist) b.length = 1.8, b.width = 0.7, b.height = 1.7;
  b.z = -1.73 + 0.5 * b.height;
  return b;
}

// Lattice steps: about 0.15 m across, 0.2 m up, a whole number of cells per side.
Eigen::Vector3d latticeStep(const Box& b) {
  return {b.length / std::ceil(b.length / 0.15), b.width / std::ceil(b.width / 0.15),
          b.height / std::ceil(b.height / 0.2)};
}

// Points at the lattice cells' centres, filling the box, intensity 0.6.
void fillBox(const Box& b, PointCloud* c) {
  const double cy = std::cos(b.yaw), sy = std::sin(b.yaw);
  const Eigen::Vector3d st = latticeStep(b);
  for (double l = -0.5 * b.length + 0.5 * st.x(); l < 0.5 * b.length; l += st.x())
    for (double w = -0.5 * b.width + 0.5 * st.y(); w < 0.5 * b.width; w += st.y())
      for (double h = -0.5 * b.height + 0.5 * st.z(); h < 0.5 * b.height; h += st.z())
        c->push_back({static_cast<float>(b.x + cy * l - sy * w), static_cast<float>(b.y + sy * l + cy * w),
                      static_cast<float>(b.z + h), 0.6f});
}

// The box shrunk by a lattice step each side: its faces lie midway between lattice points.
Box innerBox(Box b) {
  const Eigen::Vector3d st = latticeStep(b);
  b.length -= 2 * st.x(), b.width -= 2 * st.y(), b.height -= 2 * st.z();
  return b;
}

// Ground out to 40 m, boxes filled with points; a previous sweep half a metre behind (the ego drove forward).
DetectorSample makeSample(const std::vector<Box>& boxes, const std::vector<Box>& ignore = {}) {
  DetectorSample s;
  s.id = "0000/000001";
  std::mt19937 rng(7);
  std::uniform_real_distribution<float> U(0.0f, 1.0f);
  for (float x = -40; x < 40; x += 0.5f)
    for (float y = -40; y < 40; y += 0.5f) s.current.push_back({x, y, -1.73f, 0.05f + 0.9f * U(rng)});
  for (const Box& b : boxes) fillBox(b, &s.current);
  s.boxes = boxes;
  s.velocity_valid.assign(boxes.size(), true);
  s.ignore = ignore;
  s.prev_to_current = makeTransform(-0.5, 0, 0, 0.01);
  s.previous = transformCloud(s.current, s.prev_to_current.inverse());
  s.has_previous = true;
  return s;
}

std::vector<Box> someBoxes() {
  return {makeBox(ObjectClass::Car, 10, 3, 0.2), makeBox(ObjectClass::Car, -15, -6, 1.4),
          makeBox(ObjectClass::Pedestrian, 6, -4, 0.0), makeBox(ObjectClass::Cyclist, 20, 8, -0.7)};
}

bool sameCloud(const PointCloud& a, const PointCloud& b) {
  return a.size() == b.size() && std::memcmp(a.points.data(), b.points.data(), a.size() * sizeof(Point)) == 0;
}

bool sameBoxes(const std::vector<Box>& a, const std::vector<Box>& b) {
  if (a.size() != b.size()) return false;
  for (std::size_t i = 0; i < a.size(); ++i)
    if (a[i].x != b[i].x || a[i].y != b[i].y || a[i].z != b[i].z || a[i].yaw != b[i].yaw || a[i].label != b[i].label)
      return false;
  return true;
}

sim::SensorModel hdl64e() {
  return sim::loadSensorModel(std::string(RET3D_SOURCE_DIR) + "/config/sensors/hdl64e.yaml");
}

TEST(SensorAugment, WithEverythingOffTheSampleAndTheRandomStreamAreUnchanged) {
  const DetectorSample orig = makeSample(someBoxes(), {makeBox(ObjectClass::Car, -5, 12, 0)});
  DetectorSample s = orig;
  std::mt19937 rng(3), untouched(3);
  SensorAugmenter(SensorAugmentOptions()).apply(&s, &rng);
  EXPECT_TRUE(sameCloud(s.current, orig.current));
  EXPECT_TRUE(sameCloud(s.previous, orig.previous));
  EXPECT_TRUE(sameBoxes(s.boxes, orig.boxes));
  EXPECT_TRUE(sameBoxes(s.ignore, orig.ignore));
  EXPECT_EQ(s.velocity_valid, orig.velocity_valid);
  EXPECT_TRUE(s.has_previous);
  EXPECT_TRUE(s.prev_to_current.isApprox(orig.prev_to_current));
  EXPECT_TRUE(rng == untouched);  // the LWD-3D augmentations that follow draw what they drew before
}

TEST(SensorAugment, RayDropKeepsTheExpectedFraction) {
  PointCloud c;
  for (int i = 0; i < 100000; ++i) c.push_back({static_cast<float>(5 + i % 60), 0.0f, -1.0f, 0.5f});
  std::mt19937 rng(1);
  PointCloud uniform = c;
  dropRays(&uniform, 0.3, 0.0, &rng);
  EXPECT_NEAR(static_cast<double>(uniform.size()) / c.size(), 0.7, 0.01);
  // Range-dependent: far points go more often than near ones.
  PointCloud ranged = c;
  dropRays(&ranged, 0.1, 0.4, &rng);
  std::size_t near = 0, far = 0;
  for (const Point& p : ranged.points) (p.x < 20 ? near : far) += 1;
  EXPECT_GT(static_cast<double>(near) / 15, 1.2 * static_cast<double>(far) / 45);
  // Through the options, p drawn from [0.3, 0.3]: both sweeps thinned alike.
  SensorAugmentOptions o;
  o.ray_drop_min = o.ray_drop_max = 0.3;
  o.min_box_points = 0;
  DetectorSample s = makeSample({});
  const std::size_t n = s.current.size(), np = s.previous.size();
  SensorAugmenter(o).apply(&s, &rng);
  EXPECT_NEAR(static_cast<double>(s.current.size()) / n, 0.7, 0.01);
  EXPECT_NEAR(static_cast<double>(s.previous.size()) / np, 0.7, 0.01);
}

TEST(SensorAugment, BoxesThatLoseTheirPointsBecomeIgnored) {
  SensorAugmentOptions o;
  o.ray_drop_min = o.ray_drop_max = 0.97;
  o.min_box_points = 20;
  DetectorSample s = makeSample({makeBox(ObjectClass::Pedestrian, 6, -4, 0.0), makeBox(ObjectClass::Car, 10, 3, 0)});
  std::mt19937 rng(2);
  SensorAugmenter(o).apply(&s, &rng);
  // The pedestrian (270 points) keeps about 8: ignored; the car (2688) keeps about 80: still an object.
  ASSERT_EQ(s.boxes.size(), 1u);
  EXPECT_EQ(s.boxes[0].label, ObjectClass::Car);
  EXPECT_EQ(s.velocity_valid.size(), 1u);
  ASSERT_EQ(s.ignore.size(), 1u);
  EXPECT_EQ(s.ignore[0].label, ObjectClass::Pedestrian);
}

TEST(SensorAugment, BeamSubsamplingKeepsHalfTheBeams) {
  const sim::SensorModel sensor = hdl64e();
  ASSERT_EQ(sensor.beams(), 64);
  DetectorSample s;
  for (int beam = 0; beam < sensor.beams(); ++beam) {
    const double e = sensor.elevation_deg[beam] * M_PI / 180;
    for (int a = 0; a < 360; ++a) {
      const double r = 5 + a % 50, az = a * M_PI / 180;
      s.current.push_back({static_cast<float>(r * std::cos(e) * std::cos(az)),
                           static_cast<float>(r * std::cos(e) * std::sin(az)), static_cast<float>(r * std::sin(e)),
                           0.5f});
    }
  }
  const std::size_t n = s.current.size();
  SensorAugmentOptions o;
  o.beam_subsample_probability = 1.0;
  const SensorAugmenter aug(o, sensor.elevation_deg, {});
  std::mt19937 rng(5);
  aug.apply(&s, &rng);
  std::set<int> beams;
  for (const Point& p : s.current.points)
    beams.insert(sim::nearestBeam(sensor, std::atan2(p.z, std::hypot(p.x, p.y)) * 180 / M_PI));
  EXPECT_EQ(beams.size(), 32u);
  EXPECT_EQ(s.current.size(), n / 2);
  for (int b : beams) EXPECT_EQ(b % 2, *beams.begin() % 2) << "beam " << b;
}

TEST(SensorAugment, IntensityZeroingHitsTheFractionAndIntensitiesStayInRange) {
  DetectorSample s = makeSample(someBoxes());
  PointCloud c = s.current;
  std::mt19937 rng(9);
  zeroIntensities(&c, 0.15, &rng);
  std::size_t zero = 0;
  double zero_range = 0, all_range = 0;
  for (const Point& p : c.points) {
    const double r = std::hypot(p.x, p.y);
    all_range += r;
    if (p.intensity == 0.0f) ++zero, zero_range += r;
  }
  EXPECT_NEAR(static_cast<double>(zero) / c.size(), 0.15, 0.001);
  EXPECT_GT(zero_range / zero, 1.1 * all_range / c.size());  // far returns preferred

  SensorAugmentOptions o;
  o.intensity_jitter_probability = 1.0;
  o.intensity_scale_min = 1.5, o.intensity_scale_max = 2.0;  // pushes many above 1: clamped
  o.intensity_noise_sigma = 0.2;
  o.intensity_zero_probability = 1.0;
  o.intensity_zero_max = 0.2;
  SensorAugmenter(o).apply(&s, &rng);
  std::size_t zeros = 0;
  for (const PointCloud* cloud : {&s.current, &s.previous})
    for (const Point& p : cloud->points) {
      ASSERT_GE(p.intensity, 0.0f);
      ASSERT_LE(p.intensity, 1.0f);
      zeros += p.intensity == 0.0f;
    }
  EXPECT_GT(zeros, 0u);

  o = SensorAugmentOptions();
  o.intensity_constant_probability = 1.0;
  o.intensity_constant_value = 0.25;
  SensorAugmenter(o).apply(&s, &rng);
  for (const Point& p : s.current.points) ASSERT_EQ(p.intensity, 0.25f);
}

// Per-object intensity gain: the returns of the object (in both sweeps, where it was then) change, nothing else.
TEST(SensorAugment, ObjectIntensityGainScalesThatObjectsReturnsOnly) {
  const DetectorSample orig = makeSample(someBoxes());
  DetectorSample s = orig;
  const Box& ped = orig.boxes[2];
  const std::size_t changed = scaleObjectIntensity(&s, ped, 0.5, 0.1);
  EXPECT_GT(changed, 20u);
  const GtRegion region(ped, GtDatabaseOptions());
  for (const auto& [now, was, T] :
       {std::tuple{&s.current, &orig.current, Eigen::Isometry3d::Identity()},
        std::tuple{&s.previous, &orig.previous, orig.prev_to_current}}) {
    ASSERT_EQ(now->size(), was->size());
    std::size_t inside = 0;
    for (std::size_t i = 0; i < now->size(); ++i) {
      const Point& p = was->points[i];
      const Eigen::Vector3d w = T * Eigen::Vector3d(p.x, p.y, p.z);  // where it is in the current frame
      const bool in = region.contains({static_cast<float>(w.x()), static_cast<float>(w.y()),
                                       static_cast<float>(w.z()), p.intensity});
      inside += in;
      EXPECT_FLOAT_EQ(now->points[i].intensity, in ? 0.5f * p.intensity : p.intensity) << i;
    }
    EXPECT_EQ(inside, changed);  // the object stood still: as many returns in the previous sweep
  }

  // Through apply(): every object gets a gain in the range, clamped to 1; the ground keeps its intensities.
  SensorAugmentOptions o;
  o.object_intensity_probability = 1.0;
  o.object_intensity_gain_min = o.object_intensity_gain_max = 4.0;
  s = orig;
  std::mt19937 rng(5);
  SensorAugmenter(o).apply(&s, &rng);
  std::size_t brightened = 0, same = 0;
  for (std::size_t i = 0; i < s.current.size(); ++i) {
    const float a = orig.current.points[i].intensity, b = s.current.points[i].intensity;
    ASSERT_LE(b, 1.0f);
    if (b == a) ++same;
    else if (b == std::min(1.0f, 4.0f * a)) ++brightened;
    else ADD_FAILURE() << "point " << i << ": " << a << " -> " << b;
  }
  EXPECT_GT(brightened, 100u);
  EXPECT_GT(same, 20000u);
}

// Dark objects: only the listed classes' returns turn to 0, about the drawn fraction of them; the rest is untouched.
TEST(SensorAugment, DarkObjectsZeroAFractionOfTheirClassReturnsOnly) {
  const DetectorSample orig = makeSample(someBoxes());
  auto zeros = [](const PointCloud& c) {
    std::size_t n = 0;
    for (const Point& p : c.points) n += p.intensity == 0.0f;
    return n;
  };
  SensorAugmentOptions o;
  o.object_zero_probability = 1.0;
  o.object_zero_min = o.object_zero_max = 0.6;
  DetectorSample s = orig;
  std::mt19937 rng(3);
  SensorAugmenter(o).apply(&s, &rng);
  std::size_t car_returns = 0, car_zeros = 0;
  for (std::size_t i = 0; i < s.current.size(); ++i) {
    const Point& p = orig.current.points[i];
    const bool in_car = GtRegion(orig.boxes[0], GtDatabaseOptions()).contains(p) ||
                        GtRegion(orig.boxes[1], GtDatabaseOptions()).contains(p);
    if (in_car) {
      ++car_returns;
      car_zeros += s.current.points[i].intensity == 0.0f;
    } else {
      EXPECT_FLOAT_EQ(s.current.points[i].intensity, p.intensity) << i;  // pedestrian, cyclist, ground: unchanged
    }
  }
  ASSERT_GT(car_returns, 100u);
  EXPECT_NEAR(static_cast<double>(car_zeros) / static_cast<double>(car_returns), 0.6, 0.1);
  EXPECT_GT(zeros(s.previous), zeros(orig.previous));  // the previous sweep's car returns too
  // A class not listed is left alone.
  o.object_zero_classes = {ObjectClass::Cyclist};
  DetectorSample other = orig;
  SensorAugmenter(o).apply(&other, &rng);
  EXPECT_GT(zeros(other.current), zeros(orig.current));
  EXPECT_LT(zeros(other.current), zeros(s.current));
}

TEST(SensorAugment, PreviousSweepDropoutClearsItAndInvalidatesVelocities) {
  DetectorSample s = makeSample(someBoxes());
  SensorAugmentOptions o;
  o.previous_dropout_probability = 1.0;
  std::mt19937 rng(4);
  SensorAugmenter(o).apply(&s, &rng);
  EXPECT_FALSE(s.has_previous);
  EXPECT_TRUE(s.previous.empty());
  EXPECT_TRUE(s.prev_to_current.isApprox(Eigen::Isometry3d::Identity()));
  ASSERT_EQ(s.velocity_valid.size(), s.boxes.size());
  for (bool v : s.velocity_valid) EXPECT_FALSE(v);
}

TEST(SensorAugment, PoseJitterMovesPointsAndBoxesTogether) {
  const DetectorSample orig = makeSample(someBoxes());
  DetectorSample s = orig;
  SensorAugmentOptions o;
  o.pose_z_range = 0.1;
  o.pose_tilt_deg = 1.0;
  std::mt19937 rng(11);
  SensorAugmenter(o).apply(&s, &rng);
  // Boxes with faces midway between lattice points (>= 6.5 cm away), so the tilt of a point about the box centre
  // (at most 2.3 m x 1.4 degrees = 5.6 cm) does not count.
  auto inner = [](std::vector<Box> boxes) {
    for (Box& b : boxes) b = innerBox(b);
    return boxes;
  };
  const auto before = countPointsInBoxes(inner(orig.boxes), orig.current);
  const auto after = countPointsInBoxes(inner(s.boxes), s.current);
  ASSERT_EQ(before.size(), after.size());
  for (std::size_t i = 0; i < before.size(); ++i) {
    EXPECT_GT(before[i], 50u);
    EXPECT_EQ(after[i], before[i]) << i;
    EXPECT_DOUBLE_EQ(s.boxes[i].yaw, orig.boxes[i].yaw);
    EXPECT_GT(std::abs(s.boxes[i].z - orig.boxes[i].z), 1e-4);  // it did move
  }
  // The previous sweep, moved into the current frame, still lies on the current one's ground.
  const PointCloud prev = transformCloud(s.previous, s.prev_to_current);
  const auto prev_after = countPointsInBoxes(inner(s.boxes), prev);
  for (std::size_t i = 0; i < before.size(); ++i) EXPECT_EQ(prev_after[i], before[i]) << i;
}

std::vector<GtObject> someDatabase() {
  std::vector<GtObject> db;
  std::mt19937 rng(17);
  std::uniform_real_distribution<double> U(0.0, 1.0);
  for (int i = 0; i < 60; ++i) {
    const ObjectClass c = i % 3 == 0 ? ObjectClass::Car : i % 3 == 1 ? ObjectClass::Pedestrian : ObjectClass::Cyclist;
    const double r = 5 + 30 * U(rng), az = 2 * M_PI * U(rng);
    GtObject g;
    g.box = makeBox(c, r * std::cos(az), r * std::sin(az), 2 * M_PI * U(rng) - M_PI);
    PointCloud pts;
    fillBox(g.box, &pts);
    g.points = pts.points;
    g.box.num_points = static_cast<std::uint32_t>(g.points.size());
    db.push_back(g);
  }
  return db;
}

TEST(SensorAugment, GroundTruthSamplingNeverOverlapsAndThePastedBoxHoldsItsPoints) {
  SensorAugmentOptions o;
  o.gt_sample_counts = {{ObjectClass::Car, 6}, {ObjectClass::Pedestrian, 8}, {ObjectClass::Cyclist, 6}};
  o.gt_database = "given below";
  o.gt_sample_margin = 0.3;
  const SensorAugmenter aug(o, {}, someDatabase());
  // A dense scene: a row of parked cars each side, pedestrians on the pavement, an ignored van.
  std::vector<Box> boxes, ignore = {makeBox(ObjectClass::Car, 12, 0, 0)};
  for (int i = -6; i <= 6; ++i) {
    boxes.push_back(makeBox(ObjectClass::Car, 5.0 * i, 4, 0));
    boxes.push_back(makeBox(ObjectClass::Car, 5.0 * i, -4, M_PI));
    boxes.push_back(makeBox(ObjectClass::Pedestrian, 5.0 * i + 2, 7, 0.5));
  }
  std::size_t pasted_total = 0;
  for (unsigned seed = 0; seed < 40; ++seed) {
    DetectorSample s = makeSample(boxes, ignore);
    const std::size_t n0 = s.boxes.size();
    std::mt19937 rng(seed);
    aug.pasteObjects(&s, &rng);
    ASSERT_EQ(s.velocity_valid.size(), s.boxes.size());
    pasted_total += s.boxes.size() - n0;
    const PointCloud previous_here = transformCloud(s.previous, s.prev_to_current);
    for (std::size_t i = n0; i < s.boxes.size(); ++i) {
      const Box& p = s.boxes[i];
      for (std::size_t j = 0; j < s.boxes.size(); ++j)
        if (j != i) {
          ASSERT_EQ(bevIntersectionArea(p, s.boxes[j]), 0.0) << "seed " << seed << " box " << j;
        }
      for (const Box& g : s.ignore) ASSERT_EQ(bevIntersectionArea(p, g), 0.0) << "seed " << seed;
      // Its points came along (the box grown by the cut margin holds at least the database's count).
      Box grown = p;
      grown.length += 0.2, grown.width += 0.2, grown.height += 0.2;
      EXPECT_GE(countPointsInBoxes({grown}, s.current)[0], p.num_points) << "seed " << seed;
      EXPECT_GE(countPointsInBoxes({grown}, previous_here)[0], p.num_points - 2) << "seed " << seed;
    }
  }
  EXPECT_GT(pasted_total, 100u);  // the scene still leaves room: the check above is not vacuous
}

TEST(SensorAugment, TheDatabaseRoundTripsAndBadFilesAreRefused) {
  test::TempDir dir;
  const std::string path = dir / "objects.gtdb";
  const std::vector<GtObject> db = someDatabase();
  writeGtDatabase(path, db);
  const std::vector<GtObject> back = readGtDatabase(path);
  ASSERT_EQ(back.size(), db.size());
  for (std::size_t i = 0; i < db.size(); ++i) {
    EXPECT_EQ(back[i].box.label, db[i].box.label);
    EXPECT_DOUBLE_EQ(back[i].box.yaw, db[i].box.yaw);
    ASSERT_EQ(back[i].points.size(), db[i].points.size());
    EXPECT_EQ(std::memcmp(back[i].points.data(), db[i].points.data(), db[i].points.size() * sizeof(Point)), 0);
  }
  std::ofstream(dir / "bad.gtdb") << "not a database";
  EXPECT_THROW(readGtDatabase(dir / "bad.gtdb"), std::runtime_error);
  EXPECT_THROW(readGtDatabase(dir / "missing.gtdb"), std::runtime_error);
}

TEST(SensorAugment, OptionsAreReadUnderTrainAndCheckedNamingTheKey) {
  const auto o = detectorOptionsFromYaml(
      "train: {ray_drop_max: 0.3, previous_dropout_probability: 0.3, gt_database: x.gtdb,\n"
      "        gt_sample_counts: {Car: 6, Pedestrian: 8}}\n");
  EXPECT_DOUBLE_EQ(o.train.sensor_augment.ray_drop_max, 0.3);
  EXPECT_DOUBLE_EQ(o.train.sensor_augment.previous_dropout_probability, 0.3);
  EXPECT_EQ(o.train.sensor_augment.gt_sample_counts.size(), 2u);
  EXPECT_TRUE(o.train.sensor_augment.gtSamplingOn());
  for (const char* bad : {"train: {ray_drop_max: 1.5}", "train: {ray_drop_min: 0.4, ray_drop_max: 0.2}",
                          "train: {beam_subsample_keep_every: 1}", "train: {gt_sample_counts: {Car: -3}}",
                          "train: {intensity_zero_max: -0.1}", "train: {pose_tilt_deg: 20}"}) {
    try {
      detectorOptionsFromYaml(bad, "t.yaml");
      ADD_FAILURE() << bad << " was accepted";
    } catch (const std::runtime_error& e) {
      const std::string key = std::string(bad).substr(8, std::string(bad).find(':', 8) - 8);
      EXPECT_NE(std::string(e.what()).find("train." + key), std::string::npos) << e.what();
    }
  }
  const auto robust = loadDetectorOptions(std::string(RET3D_SOURCE_DIR) + "/config/detector/lwd3d_anchor_robust.yaml");
  const auto stage3 = loadDetectorOptions(std::string(RET3D_SOURCE_DIR) + "/config/detector/lwd3d_anchor_stage3.yaml");
  EXPECT_TRUE(diffModelConfigs(robust.model, stage3.model).empty());
  EXPECT_GT(robust.train.sensor_augment.ray_drop_max, 0);
}

}  // namespace
}  // namespace ret3d
