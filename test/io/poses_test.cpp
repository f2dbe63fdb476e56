#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <random>

#include "ret3d/core/transform.h"
#include "ret3d/io/kitti.h"
#include "support/parse_error_message.h"
#include "support/test_util.h"

namespace ret3d {
namespace {

namespace fs = std::filesystem;
using test::TempDir;

Eigen::Isometry3d randomPose(std::mt19937& rng) {
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  Eigen::Isometry3d t = Eigen::Isometry3d::Identity();
  t.linear() = Eigen::Quaterniond(u(rng), u(rng), u(rng), u(rng)).normalized().toRotationMatrix();
  t.translation() = Eigen::Vector3d(100 * u(rng), 100 * u(rng), 10 * u(rng));
  return t;
}

TEST(Poses, WriteReadRoundTrip) {
  TempDir tmp;
  std::mt19937 rng(3);
  std::vector<Eigen::Isometry3d> poses = {Eigen::Isometry3d::Identity()};
  for (int i = 0; i < 50; ++i) poses.push_back(randomPose(rng));
  kitti::writePoses(tmp / "0000.txt", poses);
  const auto back = kitti::readPoses(tmp / "0000.txt");
  ASSERT_EQ(back.size(), poses.size());
  for (std::size_t i = 0; i < poses.size(); ++i) {
    EXPECT_LT((back[i].matrix() - poses[i].matrix()).cwiseAbs().maxCoeff(), 1e-9) << i;
    EXPECT_EQ(back[i].matrix().row(3), Eigen::RowVector4d(0, 0, 0, 1));
  }
}

TEST(Poses, MalformedLineNamesFileLineAndField) {
  TempDir tmp;
  const std::string path = tmp / "bad.txt";
  const auto read = [&] { kitti::readPoses(path); };
  std::ofstream(path) << "1 0 0 0 0 1 0 0 0 0 1 0\n1 0 0 0.5 0 1 0 0 0 0 1\n";
  EXPECT_EQ(test::parseErrorMessage(read), path + ":2: field 'tz': missing; the line has 11 values (a 3x4 pose has 12)");
  std::ofstream(path) << "1 0 0 0 0 1 0 0 0 0 1 0\n\n1 0 0 0 0 1 0 y 0 0 1 0\n";
  EXPECT_EQ(test::parseErrorMessage(read), path + ":3: field 'ty': 'y' is not a number");
}

TEST(Poses, EveryRealPoseFileParsesAndCoversItsLabels) {
  const auto data = test::sharedDataDir();
  if (!data) GTEST_SKIP() << test::kSharedDataMissing;
  const kitti::TrackingDataset ds(*data + "/kitti_tracking");
  const auto seqs = ds.sequences();
  ASSERT_EQ(seqs.size(), 20u);
  for (const auto& s : seqs) {
    const auto poses = kitti::readPoses(ds.posePath(s));
    ASSERT_FALSE(poses.empty()) << s;
    EXPECT_TRUE(poses.front().isApprox(Eigen::Isometry3d::Identity(), 1e-6)) << s;  // first frame identity
    for (const auto& p : poses) {
      EXPECT_LT((p.linear() * p.linear().transpose() - Eigen::Matrix3d::Identity()).norm(), 1e-5) << s;
    }
    int last_frame = 0;
    for (const auto& l : kitti::readTrackingLabels(ds.labelPath(s))) last_frame = std::max(last_frame, l.frame);
    EXPECT_GT(static_cast<int>(poses.size()), last_frame) << s;  // a pose for every labelled frame
  }
}

TEST(Poses, CameraPosesToLidarConjugatesByTheRectifiedCameraTransform) {
  // Forward motion of the camera (along its z) is forward motion of the LiDAR (along its x).
  const kitti::Calibration c = kitti::defaultCalibration();
  std::vector<Eigen::Isometry3d> cam;
  for (int i = 0; i < 5; ++i) {
    Eigen::Isometry3d t = Eigen::Isometry3d::Identity();
    t.translation() = Eigen::Vector3d(0, 0, 1.5 * i);
    cam.push_back(t);
  }
  const auto lidar = kitti::cameraPosesToLidar(cam, c);
  ASSERT_EQ(lidar.size(), 5u);
  EXPECT_TRUE(lidar[0].isApprox(Eigen::Isometry3d::Identity(), 1e-12));
  EXPECT_NEAR(lidar[4].translation().x(), 6.0, 0.01);
  EXPECT_NEAR(lidar[4].translation().y(), 0.0, 0.1);
  EXPECT_NEAR(lidar[4].translation().z(), 0.0, 0.2);
  EXPECT_TRUE(lidar[4].linear().isApprox(Eigen::Matrix3d::Identity(), 1e-12));

  // A world point seen from LiDAR frame t agrees with the camera's view through the same calibration:
  // p_velo0 = T_velo0_velo_t * p_velo_t  <=>  p_cam0 = T_cam0_cam_t * p_cam_t.
  std::mt19937 rng(11);
  std::vector<Eigen::Isometry3d> cam2 = {Eigen::Isometry3d::Identity()};
  for (int i = 0; i < 3; ++i) cam2.push_back(randomPose(rng));
  const auto lidar2 = kitti::cameraPosesToLidar(cam2, c);
  const Eigen::Vector3d p_velo_t(7, -2, 0.5);
  for (std::size_t i = 0; i < cam2.size(); ++i) {
    const Eigen::Vector3d via_cam = c.rectToVelo(cam2[i] * c.veloToRect(p_velo_t));
    EXPECT_LT((lidar2[i] * p_velo_t - via_cam).norm(), 1e-5) << i;
    EXPECT_TRUE((lidar2[i].linear() * lidar2[i].linear().transpose()).isApprox(Eigen::Matrix3d::Identity(), 1e-12));
  }

  // Relative to the first pose even when the file's first pose is not identity.
  std::vector<Eigen::Isometry3d> shifted;
  const Eigen::Isometry3d offset = randomPose(rng);
  for (const auto& p : cam2) shifted.push_back(offset * p);
  const auto lidar3 = kitti::cameraPosesToLidar(shifted, c);
  for (std::size_t i = 0; i < cam2.size(); ++i) EXPECT_TRUE(lidar3[i].isApprox(lidar2[i], 1e-9)) << i;
}

struct Motion {
  double forward = 0, lateral = 0, abs_lateral = 0, abs_vertical = 0, path = 0;
};

// Frame-to-frame motion of the LiDAR, expressed in the LiDAR frame at the earlier frame; standing still is skipped.
Motion motionOf(const std::vector<Eigen::Isometry3d>& poses) {
  Motion m;
  for (std::size_t i = 1; i < poses.size(); ++i) {
    const Eigen::Vector3d d = (poses[i - 1].inverse() * poses[i]).translation();
    if (d.norm() < 0.2) continue;  // direction is noise
    m.forward += d.x();
    m.lateral += d.y();
    m.abs_lateral += std::fabs(d.y());
    m.abs_vertical += std::fabs(d.z());
    m.path += d.norm();
  }
  return m;
}

TEST(Poses, RealLidarPosesMoveForwardAlongX) {
  // Validates the camera -> LiDAR pose math on real data: a car cannot move sideways, so between consecutive frames
  // the LiDAR moves along its own +x, with little sideways or vertical motion.
  const auto data = test::sharedDataDir();
  if (!data) GTEST_SKIP() << test::kSharedDataMissing;
  const kitti::TrackingDataset ds(*data + "/kitti_tracking");
  for (const std::string seq : {"0001", "0006", "0020"}) {
    const auto poses = ds.lidarPoses(seq);
    ASSERT_GT(poses.size(), 100u) << seq;
    const Motion m = motionOf(poses);
    std::printf("sequence %s: path %.1f m, forward %.1f m, |sideways| %.2f m, |vertical| %.2f m\n", seq.c_str(), m.path,
                m.forward, m.abs_lateral, m.abs_vertical);
    ASSERT_GT(m.path, 20.0) << seq;
    EXPECT_GT(m.forward, 0.98 * m.path) << seq;
    EXPECT_LT(m.abs_lateral, 0.05 * m.path) << seq;
    EXPECT_LT(m.abs_vertical, 0.03 * m.path) << seq;
    for (const auto& p : poses) EXPECT_GT(p.linear()(2, 2), 0.98) << seq;  // the LiDAR's z stays up
  }
}

TEST(Poses, RectifiedCameraConventionMinimisesSidewaysDrift) {
  // The poses are those of the rectified camera: conjugating with R0_rect * Tr_velo_to_cam leaves a net sideways
  // drift of 0.5 % of the path over all sequences, Tr_velo_to_cam alone 1.2 % (a car's sideways motion averages 0).
  const auto data = test::sharedDataDir();
  if (!data) GTEST_SKIP() << test::kSharedDataMissing;
  const kitti::TrackingDataset ds(*data + "/kitti_tracking");
  Motion rect, unrect;
  for (const auto& seq : ds.sequences()) {
    kitti::Calibration calib = kitti::readCalibration(ds.calibPath(seq));
    const auto cam = kitti::readPoses(ds.posePath(seq));
    const Motion a = motionOf(kitti::cameraPosesToLidar(cam, calib));
    calib.R0_rect.setIdentity();
    const Motion b = motionOf(kitti::cameraPosesToLidar(cam, calib));
    rect.lateral += a.lateral;
    rect.path += a.path;
    unrect.lateral += b.lateral;
    unrect.path += b.path;
  }
  std::printf("net sideways drift / path over %.0f m: %.4f with R0_rect, %.4f without\n", rect.path,
              rect.lateral / rect.path, unrect.lateral / unrect.path);
  EXPECT_GT(rect.path, 5000.0);
  EXPECT_LT(std::fabs(rect.lateral / rect.path), 0.008);
  EXPECT_LT(std::fabs(rect.lateral), std::fabs(unrect.lateral));
}

}  // namespace
}  // namespace ret3d
