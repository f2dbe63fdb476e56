// Which detector score threshold wins (pipeline/score_threshold.h): the precedence docs/ARCHITECTURE.md tabulates,
// the same for `ret3d detect` and the detector nodelet.
#include "ret3d/pipeline/score_threshold.h"

#include <optional>

#include <gtest/gtest.h>

namespace ret3d {
namespace pipeline {
namespace {

TEST(ScoreThreshold, AnExplicitValueWinsOverTheParameterFileWhichWinsOverTheModel) {
  EXPECT_FLOAT_EQ(chooseScoreThreshold(0.5f, 0.3, true, 0.7), 0.7f);   // --score-threshold
  EXPECT_FLOAT_EQ(chooseScoreThreshold(0.5f, 0.3, false, 0.7), 0.7f);  // also without tracking
  EXPECT_FLOAT_EQ(chooseScoreThreshold(0.5f, 0.3, true, std::nullopt), 0.3f);  // config/ret3d.yaml feeds the tracker
  EXPECT_FLOAT_EQ(chooseScoreThreshold(0.5f, std::nullopt, true, std::nullopt), 0.5f);  // the model's (or config's)
  EXPECT_FLOAT_EQ(chooseScoreThreshold(0.5f, 0.0, true, std::nullopt), 0.0f);  // 0 is a value, not "unset"
}

TEST(ScoreThreshold, TheParameterFileAppliesOnlyWhenThePipelineTracks) {
  // `ret3d detect --stages base` publishes what the model publishes, as its model card reports it.
  EXPECT_FLOAT_EQ(chooseScoreThreshold(0.5f, 0.3, false, std::nullopt), 0.5f);
}

}  // namespace
}  // namespace pipeline
}  // namespace ret3d
