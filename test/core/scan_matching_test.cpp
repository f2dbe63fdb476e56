#include "ret3d/core/scan_matching.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>
#include <stdexcept>
#include <string>

#include "ret3d/core/transform.h"

namespace ret3d {
namespace {

// A street-like scene in the sensor frame: a ground plane, two building walls at an angle, car-sized blocks and
// poles, sampled at random.
PointCloud scene(std::mt19937* rng) {
  std::uniform_real_distribution<double> u(0, 1);
  PointCloud c;
  auto add = [&](double x, double y, double z) {
    c.points.push_back({static_cast<float>(x), static_cast<float>(y), static_cast<float>(z), 0.5f});
  };
  for (int i = 0; i < 20000; ++i) add(-40 + 80 * u(*rng), -20 + 40 * u(*rng), -1.73);  // ground
  for (int i = 0; i < 15000; ++i) add(-40 + 80 * u(*rng), 12 + 0.1 * u(*rng), -1.7 + 8 * u(*rng));  // left wall
  for (int i = 0; i < 15000; ++i) {  // right wall, slanted
    const double s = -40 + 80 * u(*rng);
    add(s, -10 - 0.15 * s, -1.7 + 6 * u(*rng));
  }
  for (int k = 0; k < 8; ++k) {  // blocks
    const double cx = -30 + 8 * k, cy = (k % 2 ? 6 : -5);
    for (int i = 0; i < 1500; ++i) add(cx + 4 * u(*rng), cy + 1.8 * u(*rng), -1.7 + 1.5 * u(*rng));
  }
  for (int k = 0; k < 10; ++k)  // poles
    for (int i = 0; i < 300; ++i) add(-35 + 7 * k + 0.1 * u(*rng), 9 + 0.1 * u(*rng), -1.7 + 4 * u(*rng));
  return c;
}

TEST(ScanMatching, RecoversAKnownPlanarMotion) {
  std::mt19937 rng(11);
  const PointCloud target = scene(&rng);
  // The sensor moved 1.2 m forward, 0.3 m left and turned 3 degrees: the source scan sees the scene from there.
  const Eigen::Isometry3d truth = makeTransform(1.2, 0.3, 0.0, 3.0 * M_PI / 180.0);
  PointCloud source = transformCloud(scene(&rng), truth.inverse());  // a fresh sampling of the same scene
  // The match starts from no motion at all.
  const ScanMatch m = matchScans(source, target);
  ASSERT_TRUE(m.converged);
  EXPECT_NEAR(m.source_to_target.translation().x(), 1.2, 0.05);
  EXPECT_NEAR(m.source_to_target.translation().y(), 0.3, 0.05);
  EXPECT_NEAR(yawOf(m.source_to_target), 3.0 * M_PI / 180.0, 0.3 * M_PI / 180.0);
  EXPECT_LT(m.rmse, 0.3);
}

// Garbage returns (finite, absurdly far) in either scan are neither cast to an index they do not fit nor matched.
TEST(ScanMatching, GarbageReturnsAreHarmless) {
  std::mt19937 rng(11);
  PointCloud target = scene(&rng);
  const Eigen::Isometry3d truth = makeTransform(1.2, 0.3, 0.0, 3.0 * M_PI / 180.0);
  PointCloud source = transformCloud(scene(&rng), truth.inverse());
  for (PointCloud* c : {&source, &target})
    for (float z : {1e30f, -1e30f, std::numeric_limits<float>::max()}) c->points.push_back({1.0f, 2.0f, z, 0.5f});
  const ScanMatch m = matchScans(source, target);
  ASSERT_TRUE(m.converged);
  EXPECT_NEAR(m.source_to_target.translation().x(), 1.2, 0.05);
  EXPECT_NEAR(m.source_to_target.translation().y(), 0.3, 0.05);
}

// PCL's generalized ICP behind the same interface: the same motion from the same start, in the ground plane.
TEST(ScanMatching, GicpRecoversTheSameMotion) {
  std::mt19937 rng(11);
  const PointCloud target = scene(&rng);
  const Eigen::Isometry3d truth = makeTransform(1.2, 0.3, 0.0, 3.0 * M_PI / 180.0);
  const PointCloud source = transformCloud(scene(&rng), truth.inverse());
  ScanMatchingOptions options;
  options.matcher = ScanMatcher::Gicp;
  const ScanMatch m = matchScans(source, target, Eigen::Isometry3d::Identity(), options);
  ASSERT_TRUE(m.converged);
  EXPECT_NEAR(m.source_to_target.translation().x(), 1.2, 0.05);
  EXPECT_NEAR(m.source_to_target.translation().y(), 0.3, 0.05);
  EXPECT_EQ(m.source_to_target.translation().z(), 0.0);
  EXPECT_NEAR(yawOf(m.source_to_target), 3.0 * M_PI / 180.0, 0.3 * M_PI / 180.0);
  EXPECT_GT(m.correspondences, 1000);
}

TEST(ScanMatching, MatcherNamesRoundTripAndUnknownOnesAreNamed) {
  for (const ScanMatcher m : {ScanMatcher::Icp, ScanMatcher::Gicp}) EXPECT_EQ(parseScanMatcher(scanMatcherName(m)), m);
  try {
    parseScanMatcher("ndt");
    FAIL() << "no exception";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("'ndt'"), std::string::npos) << e.what();
  }
}

TEST(ScanMatching, ReportsFailureWithoutStructure) {
  PointCloud ground;
  for (int i = 0; i < 1000; ++i)
    ground.points.push_back({static_cast<float>(i % 40), static_cast<float>(i / 40), -1.73f, 0});
  EXPECT_FALSE(matchScans(ground, ground).converged);
  ScanMatchingOptions gicp;
  gicp.matcher = ScanMatcher::Gicp;
  EXPECT_FALSE(matchScans(ground, ground, Eigen::Isometry3d::Identity(), gicp).converged);
}

}  // namespace
}  // namespace ret3d
