// Which detector score threshold wins (pipeline/score_threshold.h): the precedence docs/ARCHITECTURE.md tabulates,
// the same for `ret3d detect` and the detector nodelet.
#include "ret3d/pipeline/score_threshold.h"

#include "ret3d/detector/detector_options.h"
#include "ret3d/detector/model_file.h"
#include "ret3d/tracking/tracker_options.h"

#include <optional>

#include <gtest/gtest.h>

namespace ret3d {
namespace pipeline {
namespace {

TEST(ScoreThreshold, AnExplicitValueWinsOverTheParameterFileWhichWinsOverTheModel) {
  EXPECT_EQ(chooseScoreThreshold(0.3, true, 0.7), 0.7f);   // --score-threshold
  EXPECT_EQ(chooseScoreThreshold(0.3, false, 0.7), 0.7f);  // also without tracking
  EXPECT_EQ(chooseScoreThreshold(0.3, true, std::nullopt), 0.3f);  // config/ret3d.yaml feeds the tracker
  EXPECT_EQ(chooseScoreThreshold(std::nullopt, true, std::nullopt), std::nullopt);  // the model's (or config's)
  EXPECT_EQ(chooseScoreThreshold(0.0, true, std::nullopt), 0.0f);  // 0 is a value, not "unset"
}

TEST(ScoreThreshold, TheParameterFileAppliesOnlyWhenThePipelineTracks) {
  // `ret3d detect --stages base` publishes what the model publishes, as its model card reports it.
  EXPECT_EQ(chooseScoreThreshold(0.3, false, std::nullopt), std::nullopt);
}

TEST(ScoreThreshold, OneThresholdFromAboveTheModelReplacesItsPerClassThresholds) {
  InferenceOptions o;
  o.score_threshold = 0.5f;
  o.class_score_threshold = {{ObjectClass::Car, 0.4}};
  EXPECT_FLOAT_EQ(o.scoreThreshold(ObjectClass::Car), 0.4f);
  EXPECT_FLOAT_EQ(o.scoreThreshold(ObjectClass::Pedestrian), 0.5f);
  EXPECT_EQ(o.describeScoreThresholds(), "0.5 (Car 0.4)");
  o.setScoreThreshold(*chooseScoreThreshold(0.3, true, std::nullopt));  // the pipeline feeds its tracker
  EXPECT_FLOAT_EQ(o.scoreThreshold(ObjectClass::Car), 0.3f);
  EXPECT_FLOAT_EQ(o.scoreThreshold(ObjectClass::Pedestrian), 0.3f);
}

// Behind the shipped detector the tracker publishes a track from the score the detector alone publishes from, per
// class: the same objects count as sure either way.
TEST(ScoreThreshold, TheShippedTrackerConfirmsFromTheScoresTheShippedDetectorPublishes) {
  const std::string dir = RET3D_SOURCE_DIR;
  const InferenceOptions detector = detectorOptionsForModel(dir + "/models/lwd3d/detector.pt").inference;
  const TrackerOptions tracker = loadTrackerOptions(dir + "/config/tracker_lwd3d_pipeline.yaml");
  for (ObjectClass c : {ObjectClass::Car, ObjectClass::Pedestrian, ObjectClass::Cyclist})
    EXPECT_FLOAT_EQ(static_cast<float>(tracker.confirm_score.at(c)), detector.scoreThreshold(c)) << className(c);
}

}  // namespace
}  // namespace pipeline
}  // namespace ret3d
