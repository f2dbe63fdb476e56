// The tracker followed by InterRM as the offline pipeline runs it: ids kept, and the cost of tracker + InterRM.
#include "ret3d/pipeline/track_refiner.h"

#include <algorithm>
#include <chrono>
#include <iostream>

#include <gtest/gtest.h>

#include "ret3d/relation/intra_rm.h"

namespace ret3d {
namespace pipeline {
namespace {

Box carAt(double x, double y, float score = 0.9f) {
  Box b;
  b.x = x, b.y = y, b.z = -0.8, b.length = 4, b.width = 1.7, b.height = 1.5, b.yaw = 0;
  b.label = ObjectClass::Car;
  b.score = score;
  return b;
}

// 50 cars driving beside a moving ego vehicle: ids are kept, and an identity InterRM leaves the tracked boxes as the
// tracker gives them. Also reports the cost of tracker + InterRM (default module, 30-entry histories, 2 threads).
TEST(TrackRefiner, KeepsIdsAndReportsItsCost) {
  relation::setTorchThreads(2);
  const relation::InterRM inter(relation::InterRMArch{}, 1);  // untrained: the identity
  TrackerOptions opt;
  TrackRefiner with(opt, &inter), without(opt, nullptr);
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


TEST(TrackRefiner, InterRMSeesItsModelsHistoryLength) {
  relation::InterRMArch arch;
  arch.c_enc = 32, arch.heads = 4, arch.max_history = 7;
  const relation::InterRM inter(arch, 1);
  EXPECT_EQ(TrackRefiner(TrackerOptions{}, &inter).historyLength(), 7u);
  EXPECT_EQ(TrackRefiner(TrackerOptions{}, nullptr).historyLength(), 0u);
}

}  // namespace
}  // namespace pipeline
}  // namespace ret3d
