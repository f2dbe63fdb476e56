#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <fstream>

#include "ret3d/io/kitti.h"
#include "support/test_util.h"

namespace ret3d {
namespace {

namespace fs = std::filesystem;
using test::TempDir;

PointCloud tinyCloud() {
  PointCloud c;
  c.points.push_back({1, 2, 3, 0.5f});
  return c;
}

// A small tracking layout: sequence 0003 with scans 0 and 2, labels, calib and poses; 0005 with labels only.
void makeTrackingLayout(const std::string& training) {
  fs::create_directories(training + "/velodyne/0003");
  fs::create_directories(training + "/label_02");
  fs::create_directories(training + "/calib");
  fs::create_directories(training + "/pose");
  kitti::writeVelodyne(training + "/velodyne/0003/000000.bin", tinyCloud());
  kitti::writeVelodyne(training + "/velodyne/0003/000002.bin", tinyCloud());
  std::ofstream(training + "/velodyne/0003/notes.txt") << "not a scan\n";
  std::ofstream(training + "/label_02/0003.txt") << "";
  std::ofstream(training + "/label_02/0005.txt") << "";
  kitti::writeCalibration(training + "/calib/0003.txt", kitti::defaultCalibration());
  std::vector<Eigen::Isometry3d> cam(3, Eigen::Isometry3d::Identity());
  cam[1].translation().z() = 1.0;
  cam[2].translation().z() = 2.0;
  kitti::writePoses(training + "/pose/0003.txt", cam);
}

TEST(TrackingDataset, ListsSequencesFramesAndPaths) {
  TempDir tmp;
  makeTrackingLayout(tmp / "training");
  // The dataset root and the training folder itself both work.
  for (const std::string& root : {tmp.path(), tmp / "training"}) {
    const kitti::TrackingDataset ds(root);
    EXPECT_EQ(fs::path(ds.dir()).filename(), "training");
    EXPECT_EQ(ds.sequences(), (std::vector<std::string>{"0003", "0005"}));
    EXPECT_EQ(ds.frames("0003"), (std::vector<int>{0, 2}));
    EXPECT_TRUE(ds.frames("0005").empty());
    EXPECT_EQ(ds.velodynePath("0003", 2), tmp / "training/velodyne/0003/000002.bin");
    EXPECT_TRUE(fs::exists(ds.velodynePath("0003", 2)));
    EXPECT_EQ(ds.labelPath("0005"), tmp / "training/label_02/0005.txt");
    EXPECT_EQ(ds.calibPath("0003"), tmp / "training/calib/0003.txt");
    EXPECT_EQ(ds.posePath("0003"), tmp / "training/pose/0003.txt");
    EXPECT_EQ(ds.oxtsPath("0003"), tmp / "training/oxts/0003.txt");
    EXPECT_TRUE(ds.hasLabels("0003"));
    EXPECT_FALSE(ds.hasLabels("0004"));
    const auto poses = ds.lidarPoses("0003");
    ASSERT_EQ(poses.size(), 3u);
    EXPECT_NEAR(poses[2].translation().x(), 2.0, 0.01);  // camera forward = LiDAR forward
    EXPECT_TRUE(ds.lidarPoses("0005").empty());           // neither pose/ nor oxts/
  }
}

TEST(TrackingDataset, FallsBackToOxts) {
  TempDir tmp;
  makeTrackingLayout(tmp / "training");
  fs::remove(tmp / "training/pose/0003.txt");
  fs::create_directories(tmp / "training/oxts");
  kitti::OxtsRecord a, b;
  a.values[0] = b.values[0] = 49.0;
  a.values[1] = 8.4;
  b.values[1] = 8.4 + 10.0 / (6378137.0 * std::cos(49.0 * M_PI / 180.0) * M_PI / 180.0);  // 10 m east
  kitti::writeOxts(tmp / "training/oxts/0003.txt", {a, b});
  const kitti::TrackingDataset ds(tmp.path());
  const auto poses = ds.lidarPoses("0003");
  ASSERT_EQ(poses.size(), 2u);
  EXPECT_NEAR(poses[1].translation().norm(), 10.0, 1e-4);
  EXPECT_NEAR(poses[1].translation().x(), 10.0, 0.01);
}

TEST(TrackingDataset, PlainScanFolderIsOneSequence) {
  TempDir tmp;
  kitti::writeVelodyne(tmp / "000000.bin", tinyCloud());
  kitti::writeVelodyne(tmp / "000001.bin", tinyCloud());
  kitti::writeVelodyne(tmp / "000003.bin", tinyCloud());
  std::ofstream(tmp / "README.txt") << "not a scan\n";
  const kitti::TrackingDataset ds(tmp.path());
  EXPECT_TRUE(ds.isScanFolder());
  ASSERT_EQ(ds.sequences(), std::vector<std::string>{"0000"});
  EXPECT_EQ(ds.frames("0000"), (std::vector<int>{0, 1, 3}));
  EXPECT_TRUE(ds.frames("0001").empty());
  EXPECT_EQ(kitti::readVelodyne(ds.velodynePath("0000", 3)).size(), 1u);
  EXPECT_FALSE(ds.hasLabels("0000"));
  EXPECT_TRUE(ds.lidarPoses("0000").empty());
  EXPECT_TRUE(ds.calibration("0000").P2.isApprox(kitti::defaultCalibration().P2));
}

TEST(TrackingDataset, TrackingLayoutIsNoScanFolder) {
  TempDir tmp;
  makeTrackingLayout(tmp / "training");
  const kitti::TrackingDataset ds(tmp.path());
  EXPECT_FALSE(ds.isScanFolder());
  EXPECT_THROW(ds.calibration("0005"), std::runtime_error);  // a tracking layout needs its calib/ file
}

TEST(TrackingDataset, MissingRootThrows) {
  TempDir tmp;
  EXPECT_THROW(kitti::TrackingDataset(tmp / "nowhere"), std::runtime_error);
  EXPECT_THROW(kitti::ObjectDataset(tmp / "nowhere"), std::runtime_error);
}

TEST(TrackingDataset, SharedDataSequences) {
  const auto data = test::sharedDataDir();
  if (!data) GTEST_SKIP() << test::kSharedDataMissing;
  const kitti::TrackingDataset ds(*data + "/kitti_tracking");
  const auto seqs = ds.sequences();
  ASSERT_EQ(seqs.size(), 20u);
  EXPECT_EQ(seqs.front(), "0001");
  EXPECT_EQ(seqs.back(), "0020");
  for (const auto& s : seqs) {
    EXPECT_TRUE(ds.hasLabels(s)) << s;
    EXPECT_TRUE(fs::exists(ds.calibPath(s))) << s;
    EXPECT_TRUE(ds.frames(s).empty()) << s;  // box-level data: no scans
  }
  EXPECT_EQ(ds.lidarPoses("0001").size(), kitti::readPoses(ds.posePath("0001")).size());
}

TEST(ObjectDataset, ListsFramesAndPaths) {
  TempDir tmp;
  fs::create_directories(tmp / "velodyne");
  fs::create_directories(tmp / "label_2");
  kitti::writeVelodyne(tmp / "velodyne/000007.bin", tinyCloud());
  kitti::writeVelodyne(tmp / "velodyne/000003.bin", tinyCloud());
  std::ofstream(tmp / "label_2/000003.txt") << "";
  std::ofstream(tmp / "label_2/000010.txt") << "";  // labels without a scan (e.g. a partial download)
  const kitti::ObjectDataset ds(tmp.path());  // no training/ folder: ROOT is the training folder
  EXPECT_EQ(ds.dir(), tmp.path());
  EXPECT_EQ(ds.frames(), (std::vector<std::string>{"000003", "000007", "000010"}));
  EXPECT_EQ(ds.velodynePath("000007"), tmp / "velodyne/000007.bin");
  EXPECT_EQ(ds.labelPath("000003"), tmp / "label_2/000003.txt");
  EXPECT_EQ(ds.calibPath("000003"), tmp / "calib/000003.txt");

  // Unlabelled scans in the object layout need no calib/: they take the default calibration, as a folder of scans
  // does in the tracking layout. Once calib/ exists, a frame without its file is an error, never the default.
  const kitti::Calibration def = kitti::defaultCalibration();
  EXPECT_TRUE(ds.calibration("000007").velo_to_cam.matrix().isApprox(def.velo_to_cam.matrix()));
  EXPECT_TRUE(ds.calibration("000007").P2.isApprox(def.P2));
  fs::create_directories(tmp / "calib");
  EXPECT_THROW(ds.calibration("000007"), std::runtime_error);

  const auto data = test::sharedDataDir();
  if (!data) GTEST_SKIP() << test::kSharedDataMissing;
  const kitti::ObjectDataset real(*data + "/kitti_object");
  const std::vector<std::string> frames = real.frames();
  for (const std::string& f : test::kLabelledObjectFrames)
    EXPECT_TRUE(std::find(frames.begin(), frames.end(), f) != frames.end()) << f << " not listed";
  EXPECT_TRUE(std::is_sorted(frames.begin(), frames.end()));
  for (const auto& f : frames) {
    EXPECT_TRUE(fs::exists(real.velodynePath(f))) << f;
    EXPECT_TRUE(fs::exists(real.labelPath(f))) << f;
    EXPECT_TRUE(fs::exists(real.calibPath(f))) << f;
  }
}

}  // namespace
}  // namespace ret3d
