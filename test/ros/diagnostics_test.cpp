// StageMonitor (include/ret3d/ros/diagnostics.h): the input accounting a user reads on /diagnostics.
#include "ret3d/ros/diagnostics.h"

#include <gtest/gtest.h>

#include <map>
#include <string>

namespace ret3d {
namespace {

std::map<std::string, std::string> keyValues(const diagnostic_updater::DiagnosticStatusWrapper& status) {
  std::map<std::string, std::string> kv;
  for (const auto& v : status.values) kv[v.key] = v.value;
  return kv;
}

TEST(StageMonitor, EveryInputIsAnsweredOrDroppedUnderItsReasonAndTheKeysAddUp) {
  ros::Time::init();
  StageMonitor monitor;
  for (int i = 0; i < 7; ++i) monitor.input();
  monitor.dropped(DropReason::Superseded);
  monitor.dropped(DropReason::Superseded);
  monitor.dropped(DropReason::TooOld);
  monitor.dropped(DropReason::Error);
  monitor.processed(5.0, ros::Time::now());
  monitor.degraded("no_transform", "no transform velodyne -> odom");
  monitor.processed(7.0, ros::Time::now());
  monitor.degraded("no_transform", "no transform velodyne -> odom");
  monitor.degraded("conversion", "cloud: no intensity field");
  monitor.processed(6.0, ros::Time::now());

  const StageMonitor::Snapshot s = monitor.snapshot();
  EXPECT_EQ(s.inputs, 7u);
  EXPECT_EQ(s.processed, 3u);
  EXPECT_EQ(s.dropped(), 4u);
  EXPECT_EQ(s.inputs, s.processed + s.dropped());

  diagnostic_updater::DiagnosticStatusWrapper status;
  monitor.fill(status);
  const auto kv = keyValues(status);
  EXPECT_EQ(status.level, diagnostic_msgs::DiagnosticStatus::WARN);
  EXPECT_EQ(kv.at("frames in"), "7");
  EXPECT_EQ(kv.at("frames out"), "3");
  EXPECT_EQ(kv.at("frames dropped"), "4");
  EXPECT_EQ(kv.at("dropped.superseded"), "2");
  EXPECT_EQ(kv.at("dropped.too_old"), "1");
  EXPECT_EQ(kv.at("dropped.error"), "1");
  EXPECT_EQ(kv.at("degraded.no_transform"), "2");
  EXPECT_EQ(kv.at("degraded.conversion"), "1");
  EXPECT_EQ(kv.at("last degradation"), "cloud: no intensity field");

  // Nothing new since the last report: OK, and every drop reason still listed (0 or its count).
  diagnostic_updater::DiagnosticStatusWrapper quiet;
  monitor.fill(quiet);
  EXPECT_EQ(quiet.level, diagnostic_msgs::DiagnosticStatus::OK);
  EXPECT_EQ(keyValues(quiet).at("dropped.superseded"), "2");
  StageMonitor fresh;
  diagnostic_updater::DiagnosticStatusWrapper none;
  fresh.fill(none);
  for (const char* key : {"dropped.superseded", "dropped.too_old", "dropped.error"}) {
    EXPECT_EQ(keyValues(none).at(key), "0") << key;
  }
}

}  // namespace
}  // namespace ret3d
