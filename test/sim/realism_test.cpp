// The realism knobs of the sensor model and scene (docs/SIMULATOR.md "Realism") and the distance that measures them.
#include "ret3d/sim/realism.h"

#include <cmath>
#include <algorithm>
#include <map>

#include <gtest/gtest.h>

#include "ret3d/core/geometry.h"
#include "ret3d/io/kitti.h"
#include "ret3d/sim/ray_caster.h"
#include "ret3d/sim/scene.h"
#include "ret3d/sim/simulator.h"
#include "support/sim_info.h"
#include "support/test_util.h"

namespace ret3d {
namespace sim {
namespace {

TEST(Realism, Wasserstein1OfKnownHistograms) {
  const std::vector<double> c{0, 1, 2, 3};
  // All mass moved from bin 0 to bin 3: distance 3; half of it one bin over: 0.5.
  EXPECT_NEAR(wasserstein1(c, {1, 0, 0, 0}, {0, 0, 0, 1}), 3.0, 1e-12);
  EXPECT_NEAR(wasserstein1(c, {2, 2, 0, 0}, {0, 2, 2, 0}), 1.0, 1e-12);
  EXPECT_NEAR(wasserstein1(c, {1, 1, 0, 0}, {1, 0, 1, 0}), 0.5, 1e-12);
  // Normalised: the scale of either histogram does not matter; symmetric; zero against itself.
  EXPECT_NEAR(wasserstein1(c, {10, 0, 0, 0}, {0, 0, 0, 0.1}), 3.0, 1e-12);
  EXPECT_NEAR(wasserstein1(c, {0, 0, 0, 1}, {1, 0, 0, 0}), 3.0, 1e-12);
  EXPECT_NEAR(wasserstein1(c, {3, 1, 4, 1}, {3, 1, 4, 1}), 0.0, 1e-12);
  // Uneven bin spacing counts in the centres' unit.
  EXPECT_NEAR(wasserstein1({0, 0.5, 10}, {1, 0, 0}, {0, 0, 1}), 10.0, 1e-12);
  EXPECT_THROW(wasserstein1(c, {1, 0, 0}, {0, 0, 0, 1}), std::runtime_error);
  EXPECT_THROW(wasserstein1(c, {0, 0, 0, 0}, {0, 0, 0, 1}), std::runtime_error);
}

TEST(Realism, CompareReadsTheStatsFilesBack) {
  test::TempDir dir;
  SensorModel sensor = sensorByName("hdl64e", RET3D_SOURCE_DIR);
  // Two one-frame "datasets": points at 5 m and at 15 m, all with intensity 0 in the second.
  PointCloud near, far;
  for (int i = 0; i < 100; ++i) near.push_back(Point{5.0f, 0.01f * i, -1.7f, 0.5f});
  for (int i = 0; i < 100; ++i) far.push_back(Point{15.0f, 0.01f * i, -1.7f, 0.0f});
  ScanStats a, b;
  a.add(near, sensor, {});
  b.add(far, sensor, {});
  a.finish();
  b.finish();
  a.write((dir / "a"));
  b.write((dir / "b"));
  std::map<std::string, double> d;
  for (const auto& s : compareStats((dir / "a"), (dir / "b"))) d[s.name] = s.w1;
  EXPECT_NEAR(d.at("range"), 10.0, 0.2);
  EXPECT_NEAR(d.at("zero"), 1.0, 1e-9);       // none vs all zero-intensity
  EXPECT_NEAR(d.at("intensity"), 0.5, 0.02);  // 0.5 vs 0
  EXPECT_NEAR(d.at("height"), 0.0, 1e-9);     // same heights
  EXPECT_TRUE(std::isnan(d.at("cellpoints")));  // nothing above the ground in either: no distance
  EXPECT_THROW(compareStats((dir / "a"), (dir / "missing")), std::runtime_error);
}

// Intensities outside [0, 1] (a driver's raw counts, a negative int8) and absurd ranges land in the edge bins.
TEST(Realism, OutOfRangeValuesFallInTheEdgeBins) {
  SensorModel sensor = sensorByName("hdl64e", RET3D_SOURCE_DIR);
  PointCloud c;
  c.push_back(Point{5.0f, 0.0f, -1.7f, -3.0f});
  c.push_back(Point{5.0f, 0.0f, -1.7f, 255.0f});
  c.push_back(Point{1e30f, 0.0f, -1.7f, 0.5f});
  ScanStats s;
  s.add(c, sensor, {});
  EXPECT_EQ(s.intensity_hist.front(), 1.0);
  EXPECT_EQ(s.intensity_hist.back(), 1.0);
  EXPECT_EQ(s.range_hist.back(), 1.0);
  EXPECT_EQ(s.range_hist[5], 2.0);
}

// A flat ground plane 1.73 m below the sensor, plus optionally a porous box in front of it.
TriangleMesh groundScene(float reflectivity, float wall_porosity = -1) {
  TriangleMesh m;
  Surface g;
  g.reflectivity = reflectivity;
  m.addQuad({-100, -100, -1.73f}, {100, -100, -1.73f}, {100, 100, -1.73f}, {-100, 100, -1.73f}, g);
  if (wall_porosity >= 0) {
    Surface leaves;
    leaves.reflectivity = 0.2f;
    leaves.porosity = wall_porosity;
    Eigen::Isometry3f T = Eigen::Isometry3f::Identity();
    T.translation() = Eigen::Vector3f(12.0f, 0, 0);  // 10 to 14 m ahead, 4 m deep
    m.addBox(T, Eigen::Vector3f(4, 6, 6), leaves);
  }
  return m;
}

Sweep castOnce(const SensorModel& sensor, const TriangleMesh& mesh) {
  RayCaster caster(sensor, 2);
  caster.setStatic(mesh);
  caster.commit();
  return caster.cast(Eigen::Isometry3d::Identity(), 7, 0);
}

TEST(Realism, EgoBodyRemovesTheRaysThroughItAndOnlyThose) {
  SensorModel sensor = sensorByName("hdl64e", RET3D_SOURCE_DIR);
  sensor.ego_body_box.clear();
  const TriangleMesh mesh = groundScene(0.3f);
  const Sweep open = castOnce(sensor, mesh);
  sensor.ego_body_box = {-1.2, 1.0, -0.8, 0.8, -2.0, -0.4};
  const Sweep body = castOnce(sensor, mesh);
  RayCaster geometry(sensor, 1);
  std::size_t removed = 0;
  for (std::size_t slot = 0; slot < open.size(); ++slot) {
    const int c = static_cast<int>(slot) / open.beams, b = static_cast<int>(slot) % open.beams;
    const Eigen::Vector3d d = geometry.beamDirection(c, b);
    const bool blocked = sensor.blockedByEgoBody(d.x(), d.y(), d.z());
    if (blocked) {
      ASSERT_FALSE(body.returned[slot]) << "slot " << slot;
      removed += open.returned[slot];
    } else {
      // Every other ray is untouched, noise included.
      ASSERT_EQ(body.returned[slot], open.returned[slot]) << "slot " << slot;
      if (open.returned[slot]) {
        ASSERT_EQ(body.points[slot].x, open.points[slot].x);
      }
    }
  }
  EXPECT_GT(removed, 1000u);
  // Only the lowest beams lose returns, and more behind the sensor (the boot) than ahead.
  std::size_t behind = 0, ahead = 0;
  for (std::size_t slot = 0; slot < open.size(); ++slot) {
    if (!open.returned[slot] || body.returned[slot]) continue;
    // The box corner furthest out (1.2 m back, 0.8 m aside, 0.4 m down) is 15.5 degrees below the horizon.
    EXPECT_LT(sensor.elevation_deg[slot % open.beams], -15.5) << "a beam above the body lost its return";
    (open.points[slot].x < 0 ? behind : ahead) += 1;
  }
  EXPECT_GT(behind, ahead);
  EXPECT_FALSE(sensor.blockedByEgoBody(1, 0, 0));        // horizontal rays pass
  EXPECT_TRUE(sensor.blockedByEgoBody(-1, 0, -0.5));     // steep down and back: the boot
}

double zeroFraction(const Sweep& s, double min_range = 0) {
  std::size_t zero = 0, n = 0;
  for (std::size_t slot = 0; slot < s.size(); ++slot) {
    if (!s.returned[slot]) continue;
    const Point& p = s.points[slot];
    if (std::sqrt(p.x * p.x + p.y * p.y + p.z * p.z) < min_range) continue;
    ++n;
    zero += p.intensity == 0.0f;
  }
  return n ? static_cast<double>(zero) / n : 0.0;
}

TEST(Realism, ZeroIntensityReturnsAreKeptWithIntensityZero) {
  SensorModel sensor = sensorByName("hdl64e", RET3D_SOURCE_DIR);
  sensor.ego_body_box.clear();
  sensor.zero_intensity_below = 0;
  sensor.zero_intensity_near = 0;
  sensor.zero_intensity_far = 0;
  sensor.weak_return_zero_below = sensor.weak_return_lost_below = 0;  // the detection floor: test/sim/street_test.cpp
  const TriangleMesh dark = groundScene(0.08f);
  const Sweep plain = castOnce(sensor, dark);
  sensor.zero_intensity_below = 0.1;
  const Sweep thresholded = castOnce(sensor, dark);
  EXPECT_LT(zeroFraction(plain), 0.05);
  EXPECT_GT(zeroFraction(thresholded), zeroFraction(plain) + 0.3);
  // Kept, not dropped: the same rays return at the same places.
  for (std::size_t slot = 0; slot < plain.size(); ++slot) {
    ASSERT_EQ(plain.returned[slot], thresholded.returned[slot]);
    if (plain.returned[slot]) {
      ASSERT_EQ(plain.points[slot].z, thresholded.points[slot].z);
    }
  }
  // The far ramp: zero-intensity returns grow with range, none before its start.
  sensor.zero_intensity_below = 0;
  sensor.zero_intensity_far = 0.8;
  sensor.zero_intensity_near_range = 10;
  sensor.zero_intensity_far_range = 30;
  const Sweep ramp = castOnce(sensor, groundScene(0.5f));
  EXPECT_GT(zeroFraction(ramp, 30), 0.6);
  std::size_t near_zero = 0;
  for (std::size_t slot = 0; slot < ramp.size(); ++slot) {
    const Point& p = ramp.points[slot];
    if (ramp.returned[slot] && std::hypot(p.x, p.y) < 9 && p.intensity == 0.0f) ++near_zero;
  }
  EXPECT_EQ(near_zero, 0u);
  // A flat probability at every range.
  sensor.zero_intensity_near = sensor.zero_intensity_far = 0.3;
  EXPECT_NEAR(zeroFraction(castOnce(sensor, groundScene(0.5f))), 0.3, 0.02);
}

TEST(Realism, PorousVegetationSpreadsReturnsInDepth) {
  SensorModel sensor = sensorByName("hdl64e", RET3D_SOURCE_DIR);
  sensor.ego_body_box.clear();
  auto depths = [&](float porosity) {
    const Sweep s = castOnce(sensor, groundScene(0.3f, porosity));
    std::vector<double> x;
    for (std::size_t slot = 0; slot < s.size(); ++slot) {
      const Point& p = s.points[slot];
      // Returns from the box's front face or inside it, clear of the ground.
      if (s.returned[slot] && p.x > 9.5 && std::abs(p.y) < 2 && p.z > -1.0 && p.z < 1.0) x.push_back(p.x);
    }
    return x;
  };
  auto sd = [](const std::vector<double>& v) {
    double m = 0, q = 0;
    for (double x : v) m += x;
    m /= v.size();
    for (double x : v) q += (x - m) * (x - m);
    return std::sqrt(q / v.size());
  };
  const auto solid = depths(0.0f), porous = depths(0.7f);
  ASSERT_GT(solid.size(), 100u);
  ASSERT_GT(porous.size(), 100u);
  EXPECT_LT(sd(solid), 0.1);  // a clean surface at 10 m
  EXPECT_GT(sd(porous), 0.5);  // spread into the volume
  std::size_t deep = 0;
  for (double x : porous) {
    EXPECT_LT(x, 14.2) << "a return beyond the crown's far side";
    deep += x > 11.0;
  }
  EXPECT_GT(deep, porous.size() / 4);
}

TEST(Realism, HedgesBushesAndBollardsAddGeometryOffTheRoad) {
  SimConfig cfg = loadSimConfig(std::string(RET3D_SOURCE_DIR) + "/config/sim/urban_street.yaml");
  cfg.clutter.tree_spacing = {1e5, 1e5};  // no trees: every foliage triangle is a hedge or a bush
  cfg.materials["foliage"].porosity = 0.5;
  auto build = [&](bool clutter) {
    SimConfig c = cfg;
    c.clutter.hedge_probability = clutter ? 0.5 : 0.0;
    c.clutter.bush_spacing = clutter ? Range{5, 10} : Range{0, 0};
    c.clutter.bollard_spacing = clutter ? Range{5, 10} : Range{0, 0};
    Rng rng(9);
    Scene scene;
    layoutRoads(scene, c, rng, 60);
    buildStaticGeometry(scene, c, rng, 80, {});
    return scene;
  };
  const Scene without = build(false), with = build(true);
  EXPECT_GT(with.mesh.size(), without.mesh.size() + 500);
  std::size_t on_walk = 0, foliage = 0;
  for (std::size_t t = 0; t < with.mesh.size(); ++t) {
    if (with.mesh.surfaces[t].porosity <= 0) continue;
    for (int k = 0; k < 3; ++k) {
      const Eigen::Vector3f& v = with.mesh.vertices[with.mesh.triangles[t][k]];
      int road = 0;
      const double d = with.roadDistance(Eigen::Vector2d(v.x(), v.y()), &road);
      ++foliage;
      // Beyond the sidewalk, where no actor walks or drives.
      on_walk += d < with.roads[road].sidewalk - 0.05;
    }
  }
  EXPECT_GT(foliage, 1000u);
  EXPECT_EQ(on_walk, 0u);
}

TEST(Realism, MountJitterKeepsBoxesOnTheirPoints) {
  test::TempDir out, plain;
  SimOptions o;
  o.config = loadSimConfig(std::string(RET3D_SOURCE_DIR) + "/config/sim/urban_street.yaml");
  o.sensor = sensorByName("hdl64e", RET3D_SOURCE_DIR);
  o.frames = 2;
  o.seed = 21;
  o.threads = 2;
  o.out_dir = plain.path();
  o.config.mount_height_jitter = 0;
  o.config.mount_tilt_jitter_deg = 0;
  simulateSequence(o, 0);
  o.out_dir = out.path();
  o.config.mount_height_jitter = 0.1;  // exaggerated, so the test sees it
  o.config.mount_tilt_jitter_deg = 2.0;
  simulateSequence(o, 0);
  kitti::TrackingDataset ds(out.path()), ds0(plain.path());
  std::vector<std::pair<int, Box>> info;
  for (const test::SimInfoRow& r : test::readSimInfo(out / "training/sim_info/0000.txt")) {
    info.emplace_back(r.frame, r.box);
  }
  std::size_t checked = 0;
  for (int fr = 0; fr < 2; ++fr) {
    const PointCloud cloud = kitti::readVelodyne(ds.velodynePath("0000", fr));
    const PointCloud cloud0 = kitti::readVelodyne(ds0.velodynePath("0000", fr));
    // The ground moved in the LiDAR frame (height, pitch, roll): the median height of the near ground returns ahead,
    // behind, left and right changes.
    auto groundZ = [](const PointCloud& c, double ax, double ay) {
      std::vector<float> z;
      for (const auto& p : c.points)
        if (std::hypot(p.x, p.y) < 15 && p.x * ax + p.y * ay > 5 && p.z < -1.0) z.push_back(p.z);
      std::nth_element(z.begin(), z.begin() + z.size() / 2, z.end());
      return z[z.size() / 2];
    };
    double moved = 0;
    for (const auto& [ax, ay] : std::vector<std::pair<double, double>>{{1, 0}, {-1, 0}, {0, 1}, {0, -1}})
      moved += std::abs(groundZ(cloud, ax, ay) - groundZ(cloud0, ax, ay));
    EXPECT_GT(moved, 0.1) << "frame " << fr;
    for (const auto& [frame, b] : info) {
      if (frame != fr || b.num_points < 5) continue;
      EXPECT_GE(countPointsInBox(b, cloud), b.num_points) << "frame " << fr << " box at " << b.x << " " << b.y;
      ++checked;
    }
  }
  EXPECT_GT(checked, 20u);
}

}  // namespace
}  // namespace sim
}  // namespace ret3d
