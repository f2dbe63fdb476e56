#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <sstream>

#include "ret3d/io/kitti.h"
#include "support/parse_error_message.h"
#include "support/test_util.h"

namespace ret3d {
namespace {

namespace fs = std::filesystem;
using test::TempDir;

std::string readAll(const std::string& path) {
  std::ifstream in(path);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

void writeText(const std::string& path, const std::string& text) { std::ofstream(path) << text; }

void expectCalibNear(const kitti::Calibration& a, const kitti::Calibration& b, double tol) {
  EXPECT_TRUE(a.P2.isApprox(b.P2, tol)) << a.P2 << "\n" << b.P2;
  EXPECT_TRUE(a.R0_rect.isApprox(b.R0_rect, tol));
  EXPECT_TRUE(a.velo_to_cam.matrix().isApprox(b.velo_to_cam.matrix(), tol));
  EXPECT_TRUE(a.imu_to_velo.matrix().isApprox(b.imu_to_velo.matrix(), tol));
  for (int k = 0; k < 4; ++k) EXPECT_TRUE(a.P[k].isApprox(b.P[k], tol)) << "P" << k;
}

std::vector<std::string> realCalibFiles(const std::string& data) {
  std::vector<std::string> out;
  for (const char* dir : {"/kitti_tracking/training/calib", "/kitti_object/training/calib"}) {
    for (const auto& e : fs::directory_iterator(data + dir)) out.push_back(e.path().string());
  }
  std::sort(out.begin(), out.end());
  return out;
}

TEST(Calibration, EveryRealCalibrationFileParses) {
  const auto data = test::sharedDataDir();
  if (!data) GTEST_SKIP() << test::kSharedDataMissing;
  const auto files = realCalibFiles(*data);
  EXPECT_GE(files.size(), 20u + test::kLabelledObjectFrames.size());  // 20 tracking sequences, the object frames
  for (const auto& path : files) {
    const kitti::Calibration c = kitti::readCalibration(path);
    // KITTI's colour cameras: focal length ~700 px, principal point near the image centre.
    EXPECT_GT(c.P2(0, 0), 650.0) << path;
    EXPECT_LT(c.P2(0, 0), 760.0) << path;
    EXPECT_NEAR(c.P2(0, 2), 610.0, 20.0) << path;
    EXPECT_TRUE(c.P[2].isApprox(c.P2)) << path;
    EXPECT_NEAR(c.P[1](0, 3) / c.P[1](0, 0), -0.54, 0.01) << path;  // stereo baseline 0.54 m
    // Nearly-orthonormal rotations; camera z (forward) = LiDAR x, camera x (right) = -LiDAR y, camera y = -LiDAR z.
    EXPECT_TRUE((c.R0_rect * c.R0_rect.transpose()).isApprox(Eigen::Matrix3d::Identity(), 1e-5)) << path;
    const Eigen::Matrix3d r = c.velo_to_cam.linear();
    EXPECT_TRUE((r * r.transpose()).isApprox(Eigen::Matrix3d::Identity(), 1e-5)) << path;
    EXPECT_NEAR(r(2, 0), 1.0, 1e-3) << path;
    EXPECT_NEAR(r(0, 1), -1.0, 1e-3) << path;
    EXPECT_NEAR(r(1, 2), -1.0, 1e-3) << path;
    EXPECT_NEAR(c.imu_to_velo.translation().x(), -0.81, 0.05) << path;  // the IMU sits behind the LiDAR
  }
}

TEST(Calibration, TrackingKeyStyleReadsLikeTheObjectStyle) {
  TempDir tmp;
  const kitti::Calibration ref = kitti::defaultCalibration();
  kitti::writeCalibration(tmp / "object.txt", ref);
  // The tracking devkit's style: no colons, R_rect, Tr_velo_cam, Tr_imu_velo.
  std::string text = readAll(tmp / "object.txt");
  for (const auto& [from, to] : std::vector<std::pair<std::string, std::string>>{
           {"P0:", "P0"}, {"P1:", "P1"}, {"P2:", "P2"}, {"P3:", "P3"}, {"R0_rect:", "R_rect"},
           {"Tr_velo_to_cam:", "Tr_velo_cam"}, {"Tr_imu_to_velo:", "Tr_imu_velo"}}) {
    const auto pos = text.find(from);
    ASSERT_NE(pos, std::string::npos) << from;
    text.replace(pos, from.size(), to);
  }
  text += "\n";  // trailing blank line, as some files have
  writeText(tmp / "tracking.txt", text);
  ASSERT_EQ(text.find(':'), std::string::npos);
  expectCalibNear(kitti::readCalibration(tmp / "tracking.txt"), ref, 1e-12);
}

TEST(Calibration, WriterReaderRoundTrip) {
  TempDir tmp;
  kitti::Calibration c = kitti::defaultCalibration();
  c.P2(0, 3) = 1.0 / 3.0;
  c.velo_to_cam.translation() = Eigen::Vector3d(0.1234567891, -0.2, 0.3);
  c.imu_to_velo.translation() = Eigen::Vector3d(-0.8, 0.3, -0.8);
  c.P[0](1, 1) = 123.456;
  kitti::writeCalibration(tmp / "c.txt", c);
  const kitti::Calibration back = kitti::readCalibration(tmp / "c.txt");
  kitti::Calibration expected = c;
  expected.P[2] = c.P2;  // the writer takes P2 from the field the package uses
  expectCalibNear(back, expected, 1e-11);
  EXPECT_NE(readAll(tmp / "c.txt").find("Tr_velo_to_cam: "), std::string::npos);  // the object key style
}

TEST(Calibration, DefaultIsTheRealTrackingCalibration) {
  const kitti::Calibration d = kitti::defaultCalibration();
  EXPECT_DOUBLE_EQ(d.P2(0, 0), 721.5377);
  EXPECT_TRUE(d.P[2].isApprox(d.P2));
  const auto data = test::sharedDataDir();
  if (!data) GTEST_SKIP() << test::kSharedDataMissing;
  // Sequences 0000-0013 share one calibration (recorded the same day); 0001 is here.
  expectCalibNear(kitti::readCalibration(*data + "/kitti_tracking/training/calib/0001.txt"), d, 1e-12);
}

TEST(Calibration, MissingRequiredKeyNamesFileAndKey) {
  TempDir tmp;
  kitti::writeCalibration(tmp / "full.txt", kitti::defaultCalibration());
  const std::string full = readAll(tmp / "full.txt");
  for (const std::string key : {"P2", "R0_rect", "Tr_velo_to_cam"}) {
    std::stringstream in(full), out;
    std::string line;
    while (std::getline(in, line)) {
      if (line.rfind(key + ":", 0) != 0) out << line << "\n";
    }
    const std::string path = tmp / ("no_" + key + ".txt");
    writeText(path, out.str());
    const std::string msg = test::parseErrorMessage([&] { kitti::readCalibration(path); });
    EXPECT_EQ(msg.rfind(path + ": field '" + key + "': required key missing", 0), 0u) << msg;
  }
  // Tr_imu_to_velo is optional: identity when absent.
  std::string text = full.substr(0, full.find("Tr_imu_to_velo"));
  writeText(tmp / "no_imu.txt", text);
  EXPECT_TRUE(kitti::readCalibration(tmp / "no_imu.txt").imu_to_velo.isApprox(Eigen::Isometry3d::Identity()));
}

TEST(Calibration, MalformedValuesNameFileLineAndKey) {
  TempDir tmp;
  const std::string path = tmp / "bad.txt";
  const auto read = [&] { kitti::readCalibration(path); };
  writeText(path, "P2: 1 2 3 4 5 6 7 8 9 10 11\n");
  EXPECT_EQ(test::parseErrorMessage(read), path + ":1: field 'P2': expected 12 numbers, found 11");
  writeText(path, "P2: 1 2 3 4 5 6 7 8 9 10 11 12\nR0_rect: 1 0 0 0 1 0 0 0 x\n");
  EXPECT_EQ(test::parseErrorMessage(read), path + ":2: field 'R0_rect (value 9 of 9)': 'x' is not a number");
  writeText(path, "P2: 1 2 3 4 5 6 7 8 9 10 11 12\nP2 1 2 3 4 5 6 7 8 9 10 11 12\n");
  EXPECT_EQ(test::parseErrorMessage(read), path + ":2: field 'P2': given twice (first at line 1)");
}

// Found by fuzzing (test/fuzz/regressions/kitti_io): a singular P2 was read, and failed far from the file
// ("imageRegionWedge: P2 is singular"); a singular R0_rect or Tr_velo_to_cam gave NaN boxes.
TEST(Calibration, SingularMatricesAreRefusedNamingFileLineAndKey) {
  TempDir tmp;
  const std::string path = tmp / "singular.txt";
  const auto read = [&] { kitti::readCalibration(path); };
  kitti::Calibration c = kitti::defaultCalibration();
  c.P2.row(2).setZero();
  kitti::writeCalibration(path, c);
  EXPECT_EQ(test::parseErrorMessage(read), path + ":3: field 'P2': singular matrix");
  c = kitti::defaultCalibration();
  c.R0_rect.setZero();
  kitti::writeCalibration(path, c);
  EXPECT_NE(test::parseErrorMessage(read).find("field 'R0_rect': singular matrix"), std::string::npos);
  c = kitti::defaultCalibration();
  c.velo_to_cam.linear().col(0).setZero();
  kitti::writeCalibration(path, c);
  EXPECT_NE(test::parseErrorMessage(read).find("field 'Tr_velo_to_cam': singular matrix"), std::string::npos);
}

TEST(Calibration, VeloToRectAndBackAreInverseAndProjectionIsKitti) {
  const kitti::Calibration c = kitti::defaultCalibration();
  const Eigen::Vector3d p(12.3, -4.5, -0.7);
  const Eigen::Vector3d rect = c.veloToRect(p);
  EXPECT_NEAR(rect.z(), 12.3 - 0.27, 0.1);   // LiDAR x is camera depth; the camera sits ~0.27 m ahead
  EXPECT_NEAR(rect.x(), 4.5, 0.1);           // LiDAR left is camera -x
  EXPECT_LT((c.rectToVelo(rect) - p).norm(), 1e-12);
  const auto uv = c.projectRect(rect);
  ASSERT_TRUE(uv);
  const Eigen::Vector3d h = c.P2 * rect.homogeneous();
  EXPECT_NEAR(uv->x(), h.x() / h.z(), 1e-9);
  EXPECT_NEAR(uv->y(), h.y() / h.z(), 1e-9);
  EXPECT_GT(uv->x(), 609.0);  // right of the principal point
  EXPECT_FALSE(c.projectRect(Eigen::Vector3d(1, 0, -5)));  // behind the camera
}

}  // namespace
}  // namespace ret3d
