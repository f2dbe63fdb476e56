// The tracker -> InterRM glue, training sequences from real tracked detections, and the cost of tracker + InterRM.
#include "ret3d/train/inter_trainer.h"

#include <chrono>
#include <cmath>
#include <iostream>

#include <gtest/gtest.h>

#include "ret3d/core/geometry.h"
#include "ret3d/relation/intra_rm.h"
#include "test_util.h"

namespace ret3d {
namespace train {
namespace {

Box carAt(double x, double y, float score = 0.9f) {
  Box b;
  b.x = x, b.y = y, b.z = -0.8, b.length = 4, b.width = 1.7, b.height = 1.5, b.yaw = 0;
  b.label = ObjectClass::Car;
  b.score = score;
  return b;
}

TEST(InterTrainer, HistoryBecomesANewestFirstSequence) {
  std::vector<TimedBox> h(3);
  for (int k = 0; k < 3; ++k) h[static_cast<std::size_t>(k)] = {carAt(k, 0), -0.1 * (2 - k)};
  const Box current = carAt(2.05, 0.01);
  const relation::InterRMSequence s = toInterRMSequence(h, &current);
  ASSERT_EQ(s.boxes.size(), 3u);
  EXPECT_DOUBLE_EQ(s.boxes[0].x, 2.05);  // the tracked box itself
  EXPECT_DOUBLE_EQ(s.dt[0], 0.0);
  EXPECT_DOUBLE_EQ(s.boxes[2].x, 0.0);
  EXPECT_NEAR(s.dt[2], -0.2, 1e-12);
  // A track without stored history still gets a one-entry sequence.
  EXPECT_EQ(toInterRMSequence({}, &current).boxes.size(), 1u);
}

// 50 cars driving beside a moving ego vehicle: ids are kept, and an identity InterRM leaves the tracked boxes as the
// tracker gives them. Also reports the cost of tracker + InterRM (default module, 30-entry histories, 2 threads).
TEST(InterTrainer, TrackingRefinerKeepsIdsAndReportsItsCost) {
  relation::setTorchThreads(2);
  const relation::InterRM inter(relation::InterRMArch{}, 1);  // untrained: the identity
  TrackerOptions opt;
  TrackingRefiner with(opt, &inter), without(opt, nullptr);
  const int frames = 40;
  double worst_ms = 0, sum_ms = 0;
  std::vector<std::uint32_t> first_ids;
  for (int f = 0; f < frames; ++f) {
    const double t = 0.1 * f, ego_x = 15.0 * t;
    Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
    pose.translation() = Eigen::Vector3d(ego_x, 0, 0);
    std::vector<Box> dets;
    for (int i = 0; i < 50; ++i) {
      // Fixed-frame x = 10 * (i % 10) + 10 m/s * t, lanes 5 m apart; observed in the sensor frame.
      dets.push_back(carAt(10.0 * (i % 10) + 10.0 * t - ego_x, -10.0 + 5.0 * (i / 10)));
    }
    const auto t0 = std::chrono::steady_clock::now();
    const auto a = with.update(dets, t, pose);
    const double ms = 1000 * std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    const auto b = without.update(dets, t, pose);
    ASSERT_EQ(a.size(), b.size());
    for (std::size_t i = 0; i < a.size(); ++i) {
      EXPECT_EQ(a[i].track_id, b[i].track_id);
      EXPECT_NEAR(a[i].x, b[i].x, 1e-9);
    }
    if (f == 0) {
      for (const Box& x : a) first_ids.push_back(x.track_id);
    } else {
      ASSERT_EQ(a.size(), first_ids.size());
      for (std::size_t i = 0; i < a.size(); ++i) EXPECT_EQ(a[i].track_id, first_ids[i]) << "frame " << f;
    }
    if (f >= 30) worst_ms = std::max(worst_ms, ms), sum_ms += ms;  // full 30-entry histories
  }
  std::cout << "tracker + InterRM (C_enc 256, 16 heads), 50 tracks x 30 entries, 2 threads: mean "
            << sum_ms / (frames - 30) << " ms, worst " << worst_ms << " ms per frame\n";
}

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
