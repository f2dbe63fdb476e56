// The tracker config `ret3d detect|bench|autolabel` run without --tracker-config: the nodelets' one with the base
// stage, the built-in values for external detections.
#include "ret3d/pipeline/tracker_default.h"

#include <filesystem>
#include <fstream>
#include <stdexcept>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "ret3d/tracking/tracker_options.h"
#include "support/error_message.h"
#include "support/test_util.h"

namespace ret3d {
namespace pipeline {
namespace {

const std::string kPackage = RET3D_SOURCE_DIR;
using Stages = std::vector<std::string>;

TEST(TrackerDefault, TheBaseStageTracksWithTheNodeletsConfig) {
  const std::string expected = (std::filesystem::path(kPackage) / "config/tracker_lwd3d_pipeline.yaml").string();
  // parseStages("base,intra,track"), and the others as parsed ("inter" implies the tracker).
  for (const Stages& stages : {Stages{"base", "intra", "track"}, Stages{"base", "track"}, Stages{"base", "inter"}})
    EXPECT_EQ(defaultTrackerConfig(stages, kPackage), expected) << stages.size();
  // The nodelets run the file config/ret3d.yaml names: offline and online agree.
  const std::string params = test::readText(kPackage + "/config/ret3d.yaml");
  EXPECT_NE(params.find("tracker_config: $(find ret3d)/" + std::string(kPipelineTrackerConfig)), std::string::npos);
  // And it differs from the built-in values where it matters here: it keeps low probabilities.
  const TrackerOptions pipeline = loadTrackerOptions(expected), built_in;
  EXPECT_LT(pipeline.birth_score.car, built_in.birth_score.car);
}

TEST(TrackerDefault, ExternalDetectionsKeepTheBuiltInValues) {
  for (const Stages& stages : {Stages{"track"}, Stages{"intra", "track"}, Stages{"intra", "inter"}})
    EXPECT_EQ(defaultTrackerConfig(stages, kPackage), "") << stages.size();
  EXPECT_EQ(defaultTrackerConfig({"intra", "track"}, ""), "");  // no package needed
}

TEST(TrackerDefault, AMissingPackageIsAClearError) {
  const std::string msg = test::errorMessage([&] { defaultTrackerConfig({"base", "track"}, ""); });
  EXPECT_NE(msg.find("--tracker-config"), std::string::npos) << msg;
  test::TempDir tmp;
  try {
    defaultTrackerConfig({"base", "track"}, tmp.path());
    FAIL() << "no error without the file";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("tracker_lwd3d_pipeline.yaml: no such file"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace pipeline
}  // namespace ret3d
