#include "ret3d/core/scan_matching.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>
#include <stdexcept>
#include <string>

#include "ret3d/core/transform.h"
#include "support/street_scene.h"

namespace ret3d {
namespace {

PointCloud scene(std::mt19937* rng) { return test::streetScene(rng); }

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
