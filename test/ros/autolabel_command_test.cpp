// `ret3d autolabel`, run as the built command line (RET3D_CLI) with real (untrained) tiny models on the tiny
// sequence, as a tracking layout with poses and as a plain folder of scans: what it writes is a dataset the detector
// trainer loads, one labelled frame per scan.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "ret3d/detector/detector_options.h"
#include "ret3d/io/kitti.h"
#include "ret3d/train/detector_dataset.h"
#include "support/ros_test_util.h"
#include "support/test_util.h"
#include "support/tiny_models.h"
#include "support/tiny_sequence.h"

namespace ret3d {
namespace {

namespace fs = std::filesystem;
constexpr int kScans = 8;

class AutolabelCommand : public ::testing::Test {
 protected:
  void SetUp() override {
    seq_.write(tmp_ / "tracking", "0004", kScans, /*with_labels=*/false);
    fs::create_directories(tmp_ / "models");
    test::writeTinyModels(tmp_ / "models", RET3D_SOURCE_DIR);
    // The untrained detector's scores are low: every box may start a track.
    std::ifstream in(std::string(RET3D_SOURCE_DIR) + "/config/tracker.yaml");
    std::stringstream ss;
    ss << in.rdbuf();
    std::string yaml = ss.str();
    for (const std::string key : {"score_threshold: 0.1", "birth_score: 0.75"}) {
      const auto pos = yaml.find(key);
      ASSERT_NE(pos, std::string::npos) << "config/tracker.yaml has no '" << key << "'";
      yaml.replace(pos, key.size(), key.substr(0, key.find(':')) + ": 0.0");
    }
    std::ofstream(tmp_ / "tracker.yaml") << yaml;
  }

  // `ret3d COMMAND` (autolabel or detect) on `data` into `out` with the tiny models; every box the untrained
  // detector finds is tracked (and, by autolabel, kept and labelled).
  int run(const std::string& command_name, const std::string& data, const std::string& out, std::string* output,
          const std::vector<std::string>& extra = {}) {
    std::vector<std::string> command = {
        RET3D_CLI, command_name, "--data", data, "--out", out, "--models", tmp_ / "models", "--detector-config",
        tmp_ / "models/detector.yaml", "--threads", "1", "--score-threshold", "0", "--tracker-config",
        tmp_ / "tracker.yaml"};
    if (command_name == "autolabel")
      command.insert(command.end(), {"--min-track-length", "1", "--min-track-score", "0"});
    command.insert(command.end(), extra.begin(), extra.end());
    const std::string log = out + ".log";
    const int code = test::runLogged(command, log, 120.0);
    std::ifstream in(log);
    std::stringstream ss;
    ss << in.rdbuf();
    *output = ss.str();
    return code;
  }
  int autolabel(const std::string& data, const std::string& out, std::string* output,
                const std::vector<std::string>& extra = {}) {
    return run("autolabel", data, out, output, extra);
  }

  // The scans of the tiny sequence as a plain folder (no poses, no calibration).
  void writeScanFolder(const std::string& dir) {
    fs::create_directories(dir);
    for (int f = 0; f < kScans; ++f) {
      char name[16];
      std::snprintf(name, sizeof(name), "%06d.bin", f);
      fs::copy_file(tmp_ / ("tracking/training/velodyne/0004/" + std::string(name)), dir + "/" + name);
    }
  }

  // The written dataset as the detector trainer reads it.
  void expectTrainable(const std::string& out, const std::string& seq, const std::string& output) {
    const DetectorOptions options = loadDetectorOptions(tmp_ / "models/detector.yaml");
    const DetectorDataset ds(out, options.model);
    ASSERT_EQ(ds.size(), static_cast<std::size_t>(kScans));
    const DetectorSample first = ds.load(0), second = ds.load(1);
    EXPECT_EQ(first.current.size(), seq_.scans[0].size()) << "the scans are linked, not rewritten";
    EXPECT_TRUE(second.has_previous);
    const auto labels = kitti::readTrackingLabels(out + "/training/label_02/" + seq + ".txt");
    ASSERT_FALSE(labels.empty()) << output;
    for (const kitti::Label& l : labels) {
      ASSERT_TRUE(l.score.has_value());
      EXPECT_GE(l.track_id, 0);
      EXPECT_TRUE(classFromName(l.type).has_value()) << l.type;
    }
    EXPECT_EQ(kitti::readPoses(out + "/training/pose/" + seq + ".txt").size(), static_cast<std::size_t>(kScans));
  }

  test::TempDir tmp_;
  test::TinySequence seq_;
};

TEST_F(AutolabelCommand, TrackingLayoutBecomesATrainableDataset) {
  std::string output;
  ASSERT_EQ(autolabel(tmp_ / "tracking", tmp_ / "out", &output), 0) << output;
  EXPECT_NE(output.find("tracks"), std::string::npos) << output;
  EXPECT_NE(output.find("boxes per frame"), std::string::npos) << output;
  expectTrainable(tmp_ / "out", "0004", output);
  EXPECT_TRUE(fs::is_symlink(tmp_ / "out/training/velodyne/0004/000000.bin"));
}

TEST_F(AutolabelCommand, ScanFolderGetsEstimatedPosesAndDefaultCalibration) {
  writeScanFolder(tmp_ / "scans");
  std::string output;
  ASSERT_EQ(autolabel(tmp_ / "scans", tmp_ / "out", &output), 0) << output;
  EXPECT_NE(output.find("ego motion estimated"), std::string::npos) << output;
  expectTrainable(tmp_ / "out", "0000", output);
  EXPECT_TRUE(kitti::readCalibration(tmp_ / "out/training/calib/0000.txt").P2.isApprox(kitti::defaultCalibration().P2));
}

// `ret3d detect` runs the same pipeline as autolabel: on scans without poses it estimates the ego motion the same
// way and tracks, or takes the poses from --poses.
TEST_F(AutolabelCommand, DetectTracksAScanFolderWithoutPosesAsAutolabelDoes) {
  writeScanFolder(tmp_ / "scans");
  std::string output;
  ASSERT_EQ(run("detect", tmp_ / "scans", tmp_ / "pred", &output, {"--stages", "base,intra,track,inter"}), 0) << output;
  EXPECT_NE(output.find("estimating the ego motion from the scans"), std::string::npos) << output;
  EXPECT_NE(output.find("ego motion estimated"), std::string::npos) << output;
  const auto labels = kitti::readTrackingLabels(tmp_ / "pred/0000.txt");
  ASSERT_FALSE(labels.empty()) << output;
  for (const kitti::Label& l : labels) EXPECT_GE(l.track_id, 0) << "every box of the track stage has a track id";

  // The poses given: no estimation, the same frames tracked.
  ASSERT_EQ(run("detect", tmp_ / "scans", tmp_ / "pred_poses", &output,
                {"--stages", "base,intra,track,inter", "--poses", tmp_ / "tracking/training/pose/0004.txt"}),
            0)
      << output;
  EXPECT_EQ(output.find("estimating the ego motion"), std::string::npos) << output;
  EXPECT_FALSE(kitti::readTrackingLabels(tmp_ / "pred_poses/0000.txt").empty()) << output;

  // A pose file that is not there, or shorter than the scans, is refused by name.
  EXPECT_NE(run("detect", tmp_ / "scans", tmp_ / "pred_bad", &output,
                {"--stages", "base,track", "--poses", tmp_ / "missing.txt"}),
            0);
  EXPECT_NE(output.find("missing.txt"), std::string::npos) << output;
  std::ofstream(tmp_ / "short.txt") << "1 0 0 0 0 1 0 0 0 0 1 0\n";
  EXPECT_NE(run("detect", tmp_ / "scans", tmp_ / "pred_bad", &output,
                {"--stages", "base,track", "--poses", tmp_ / "short.txt"}),
            0);
  EXPECT_NE(output.find("beyond its 1 ego poses"), std::string::npos) << output;
}

TEST_F(AutolabelCommand, RefusesAnObjectLayoutAndStagesWithoutTracking) {
  std::string output;
  fs::create_directories(tmp_ / "object/training/velodyne");
  kitti::writeVelodyne(tmp_ / "object/training/velodyne/000000.bin", seq_.scans[0]);
  EXPECT_NE(autolabel(tmp_ / "object", tmp_ / "out_object", &output), 0);
  EXPECT_NE(output.find("no sequences with scans"), std::string::npos) << output;
  EXPECT_NE(autolabel(tmp_ / "tracking", tmp_ / "out_base", &output, {"--stages", "base,intra"}), 0);
  EXPECT_NE(output.find("--stages needs track or inter"), std::string::npos) << output;
}

}  // namespace
}  // namespace ret3d
