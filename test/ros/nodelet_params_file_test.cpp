// The nodelets' parameter file read offline (ros/params.h nodeletParamsScoreThreshold): `ret3d detect` with the track
// stage feeds its tracker from the threshold config/ret3d.yaml gives the detector nodelet.
#include <filesystem>
#include <fstream>
#include <string>

#include <gtest/gtest.h>

#include "ret3d/ros/params.h"
#include "support/error_message.h"
#include "support/test_util.h"

namespace ret3d {
namespace {

TEST(NodeletParamsFile, TheDetectorThresholdOfThePackagesParameterFile) {
  const std::optional<double> online = nodeletParamsScoreThreshold(RET3D_SOURCE_DIR);
  ASSERT_TRUE(online.has_value());
  EXPECT_GT(*online, 0.0);
  EXPECT_LT(*online, 0.5);  // below models/lwd3d's own published threshold: the tracker continues weak tracks
  test::TempDir tmp;
  EXPECT_FALSE(nodeletParamsScoreThreshold(tmp.path()));  // no config/ret3d.yaml
  EXPECT_FALSE(nodeletParamsScoreThreshold(""));
  std::filesystem::create_directories(tmp / "config");
  std::ofstream(tmp / "config/ret3d.yaml") << "ret3d_detector:\n  nms_iou: 0.1\n";
  EXPECT_FALSE(nodeletParamsScoreThreshold(tmp.path()));  // no key
  std::ofstream(tmp / "config/ret3d.yaml") << "ret3d_detector:\n  score_threshold: 0.25\n";
  EXPECT_DOUBLE_EQ(nodeletParamsScoreThreshold(tmp.path()).value_or(-1), 0.25);
  std::ofstream(tmp / "config/ret3d.yaml") << "ret3d_detector:\n  score_threshold: 1.5\n";
  const std::string msg = test::errorMessage([&] { nodeletParamsScoreThreshold(tmp.path()); });
  EXPECT_NE(msg.find("score_threshold"), std::string::npos) << msg;
}

}  // namespace
}  // namespace ret3d
