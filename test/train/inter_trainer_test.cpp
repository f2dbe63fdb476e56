// InterRM's training sequences from real tracked detections.
#include "ret3d/train/inter_trainer.h"

#include <gtest/gtest.h>

#include "ret3d/core/geometry.h"
#include "support/test_util.h"

namespace ret3d {
namespace train {
namespace {

TEST(InterTrainer, RealTrackedSequencesHaveTargetsAndTimeOffsets) {
  const auto data = test::sharedDataDir();
  if (!data) GTEST_SKIP() << test::kSharedDataMissing;
  InterDataOptions d;
  d.data_dir = *data + "/kitti_tracking";
  d.detections_dir = *data + "/kitti_tracking/detections/pointrcnn";
  d.sequences = {"0001"};
  relation::InterRMTrainConfig cfg;
  const auto samples = loadInterSamples(d, cfg);
  ASSERT_GT(samples.size(), 300u);
  std::size_t with_history = 0;
  for (const auto& s : samples) {
    ASSERT_FALSE(s.sequence.boxes.empty());
    EXPECT_EQ(s.sequence.dt[0], 0.0);
    for (std::size_t k = 1; k < s.sequence.dt.size(); ++k) EXPECT_LT(s.sequence.dt[k], s.sequence.dt[k - 1]);
    EXPECT_EQ(s.target.label, s.sequence.boxes[0].label);
    EXPECT_GE(bevIoU(s.sequence.boxes[0], s.target), 0.3 - 1e-9);
    with_history += s.sequence.boxes.size() > 1;
  }
  // Most matched objects have been tracked for a while.
  EXPECT_GT(with_history, samples.size() * 8 / 10);
}

}  // namespace
}  // namespace train
}  // namespace ret3d
