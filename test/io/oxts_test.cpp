#include <gtest/gtest.h>

#include <cmath>
#include <fstream>

#include "ret3d/io/kitti.h"
#include "support/parse_error_message.h"
#include "support/test_util.h"

namespace ret3d {
namespace {

using test::TempDir;

constexpr double kEarthRadius = 6378137.0;

kitti::OxtsRecord record(double lat, double lon, double alt, double yaw) {
  kitti::OxtsRecord r;
  r.values[0] = lat;
  r.values[1] = lon;
  r.values[2] = alt;
  r.values[5] = yaw;
  r.values[25] = 4;  // navstat
  r.values[26] = 10;  // numsats
  return r;
}

kitti::Calibration identityImu() {
  kitti::Calibration c = kitti::defaultCalibration();
  c.imu_to_velo = Eigen::Isometry3d::Identity();
  return c;
}

TEST(Oxts, StraightDriveEastIsForwardMotion) {
  // Heading east (yaw 0) along the parallel 49 N (Karlsruhe), 2 m per record.
  const double lat = 49.0;
  const double metres_per_degree_lon = kEarthRadius * std::cos(lat * M_PI / 180.0) * M_PI / 180.0;
  std::vector<kitti::OxtsRecord> recs;
  for (int i = 0; i < 20; ++i) recs.push_back(record(lat, 8.4 + 2.0 * i / metres_per_degree_lon, 110.0, 0.0));
  const auto poses = kitti::oxtsToLidarPoses(recs, identityImu());
  ASSERT_EQ(poses.size(), recs.size());
  for (int i = 0; i < 20; ++i) {
    EXPECT_NEAR(poses[i].translation().x(), 2.0 * i, 1e-6) << i;
    EXPECT_NEAR(poses[i].translation().y(), 0.0, 1e-6) << i;
    EXPECT_NEAR(poses[i].translation().z(), 0.0, 1e-9) << i;
    EXPECT_TRUE(poses[i].linear().isApprox(Eigen::Matrix3d::Identity(), 1e-12));
  }

  // With the real IMU mounting, the same motion seen by the LiDAR: T = Ti * T_imu * Ti^-1, so the translation is the
  // IMU translation rotated into the LiDAR axes (the lever arm cancels for a pure translation).
  const kitti::Calibration real = kitti::defaultCalibration();
  const auto velo = kitti::oxtsToLidarPoses(recs, real);
  const Eigen::Vector3d expected = real.imu_to_velo.linear() * Eigen::Vector3d(38.0, 0, 0);
  EXPECT_LT((velo.back().translation() - expected).norm(), 1e-4);
}

TEST(Oxts, HeadingNorthAndClimbing) {
  // yaw = pi/2 faces north; driving north is then again forward (+x) in the vehicle frame; altitude is up (+z).
  const double metres_per_degree_lat = kEarthRadius * M_PI / 180.0;  // at the scale of the first latitude
  std::vector<kitti::OxtsRecord> recs;
  for (int i = 0; i < 5; ++i) recs.push_back(record(49.0 + 1.0 * i / metres_per_degree_lat, 8.4, 110.0 + 0.1 * i, M_PI / 2));
  const auto poses = kitti::oxtsToLidarPoses(recs, identityImu());
  // Mercator northing at scale cos(lat0): dy = er * cos(lat0) * dlat / cos(lat) ~ 1 m per record.
  EXPECT_NEAR(poses[4].translation().x(), 4.0, 1e-3);
  EXPECT_NEAR(poses[4].translation().y(), 0.0, 1e-6);
  EXPECT_NEAR(poses[4].translation().z(), 0.4, 1e-9);
}

TEST(Oxts, TurningLeftRotatesAboutZ) {
  std::vector<kitti::OxtsRecord> recs = {record(49.0, 8.4, 100, 0.3), record(49.0, 8.4, 100, 0.3 + M_PI / 2)};
  const auto poses = kitti::oxtsToLidarPoses(recs, identityImu());
  EXPECT_NEAR(std::atan2(poses[1].linear()(1, 0), poses[1].linear()(0, 0)), M_PI / 2, 1e-12);
  // Roll and pitch compose as Rz * Ry * Rx: a pitched-up vehicle's x axis points up.
  kitti::OxtsRecord pitched = record(49.0, 8.4, 100, 0.0);
  pitched.values[4] = -0.1;  // pitch about y: negative pitch raises the nose (right-handed, y left)
  const auto p2 = kitti::oxtsToLidarPoses({record(49.0, 8.4, 100, 0.0), pitched}, identityImu());
  EXPECT_NEAR(p2[1].linear()(2, 0), std::sin(0.1), 1e-12);
}

TEST(Oxts, WriteReadRoundTripAndErrors) {
  TempDir tmp;
  std::vector<kitti::OxtsRecord> recs;
  for (int i = 0; i < 3; ++i) {
    kitti::OxtsRecord r = record(49.015003823272 + 1e-6 * i, 8.4342971002335, 116.43032836914, 0.1 * i);
    for (int k = 6; k < 25; ++k) r.values[k] = 0.01 * k * (i + 1);
    recs.push_back(r);
  }
  kitti::writeOxts(tmp / "0000.txt", recs);
  const auto back = kitti::readOxts(tmp / "0000.txt");
  ASSERT_EQ(back.size(), 3u);
  for (int i = 0; i < 3; ++i) {
    for (int k = 0; k < 30; ++k) EXPECT_NEAR(back[i].values[k], recs[i].values[k], 1e-12) << i << "," << k;
  }
  const std::string path = tmp / "bad.txt";
  std::ofstream(path) << "49 8 100 0 0 0\n";
  const std::string msg = test::parseErrorMessage([&] { kitti::readOxts(path); });
  EXPECT_EQ(msg.rfind(path + ":1: field 'vn': missing", 0), 0u) << msg;
  EXPECT_TRUE(kitti::oxtsToLidarPoses({}, kitti::defaultCalibration()).empty());
}

}  // namespace
}  // namespace ret3d
