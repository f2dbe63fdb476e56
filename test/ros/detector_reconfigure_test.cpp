// cfg/Detector.cfg repeats the ranges InferenceOptions keeps (dynamic_reconfigure needs them in the .cfg to clamp and
// to draw its sliders): they must stay the same, or rqt_reconfigure offers values the detector refuses.
#include <gtest/gtest.h>

#include "ret3d/DetectorConfig.h"
#include "ret3d/detector/detector_options.h"

namespace ret3d {
namespace {

TEST(DetectorReconfigure, TheCfgRangesAndDefaultsAreTheInferenceOptions) {
  const ret3d::DetectorConfig lo = ret3d::DetectorConfig::__getMin__(), hi = ret3d::DetectorConfig::__getMax__(),
                              start = ret3d::DetectorConfig::__getDefault__();
  EXPECT_EQ(lo.score_threshold, InferenceOptions::kScoreThreshold.lo);
  EXPECT_EQ(hi.score_threshold, InferenceOptions::kScoreThreshold.hi);
  EXPECT_EQ(lo.nms_iou, InferenceOptions::kNmsIou.lo);
  EXPECT_EQ(hi.nms_iou, InferenceOptions::kNmsIou.hi);
  const InferenceOptions defaults;
  EXPECT_FLOAT_EQ(static_cast<float>(start.score_threshold), defaults.score_threshold);
  EXPECT_DOUBLE_EQ(start.nms_iou, defaults.nms_iou);
}

}  // namespace
}  // namespace ret3d
