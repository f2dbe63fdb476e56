// A sequence's ego poses for the tracker: a given file, pose/, or estimated from the scans of a folder without them.
#include "ret3d/io/ego_motion.h"

#include <gtest/gtest.h>

#include <cstdio>
#include <filesystem>
#include <random>
#include <string>
#include <vector>

#include "ret3d/core/transform.h"
#include "support/street_scene.h"
#include "support/test_util.h"

namespace ret3d {
namespace io {
namespace {

// Four scans of one street seen by a sensor driving 1 m per frame and turning 1 degree per frame, as a plain folder.
class EgoMotion : public ::testing::Test {
 protected:
  void SetUp() override {
    std::filesystem::create_directories(dir_ / "scans");
    std::mt19937 rng(3);
    for (int f = 0; f < 4; ++f) {
      truth_.push_back(makeTransform(1.0 * f, 0.0, 0.0, f * M_PI / 180.0));
      char name[16];
      std::snprintf(name, sizeof(name), "%06d.bin", f);
      kitti::writeVelodyne(dir_ / ("scans/" + std::string(name)), transformCloud(test::streetScene(&rng),
                                                                                  truth_.back().inverse()));
    }
  }
  test::TempDir dir_;
  std::vector<Eigen::Isometry3d> truth_;
};

TEST_F(EgoMotion, AFolderWithoutPosesGetsThemFromItsScans) {
  const kitti::TrackingDataset ds(dir_ / "scans");
  ASSERT_TRUE(ds.lidarPoses("0000").empty());
  const auto poses = sequenceLidarPoses(ds, "0000");
  ASSERT_EQ(poses.size(), 4u);
  for (int f = 0; f < 4; ++f) {
    EXPECT_NEAR(poses[f].translation().x(), truth_[f].translation().x(), 0.1) << f;
    EXPECT_NEAR(poses[f].translation().y(), truth_[f].translation().y(), 0.1) << f;
    EXPECT_NEAR(yawOf(poses[f]), yawOf(truth_[f]), 0.5 * M_PI / 180.0) << f;
  }
  EXPECT_TRUE(sequenceLidarPoses(ds, "0000", {"", /*scan_matching=*/false}).empty());
}

TEST_F(EgoMotion, AGivenFileWinsAndAMissingOneIsNamed) {
  const kitti::TrackingDataset ds(dir_ / "scans");
  // Camera poses in the KITTI odometry convention, as pose/SSSS.txt holds them: read through the calibration.
  kitti::writePoses(dir_ / "poses.txt", truth_);
  const auto poses = sequenceLidarPoses(ds, "0000", {dir_ / "poses.txt", true});
  const auto expected = kitti::cameraPosesToLidar(truth_, ds.calibration("0000"));
  ASSERT_EQ(poses.size(), expected.size());
  for (std::size_t f = 0; f < poses.size(); ++f) EXPECT_TRUE(poses[f].isApprox(expected[f], 1e-9)) << f;
  try {
    sequenceLidarPoses(ds, "0000", {dir_ / "missing.txt", true});
    FAIL() << "no error";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("missing.txt"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace io
}  // namespace ret3d
