// `ret3d bench --bag FILE`, run as the built command line (RET3D_CLI) on a tiny tracking sequence this test converts
// to a bag itself, with real (untrained) model files on a small grid: the bench starts its own ROS master, plays the
// bag from a player process through the real nodelets in one manager, and reports every stage, the end-to-end
// latency, the frames and the CPU use. No ROS master is needed beforehand.
#include <gtest/gtest.h>
#include <yaml-cpp/yaml.h>

#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "ret3d/ros/kitti_bag.h"
#include "support/ros_test_util.h"
#include "support/test_util.h"
#include "support/tiny_models.h"
#include "support/tiny_sequence.h"

namespace ret3d {
namespace {

constexpr int kClouds = 12;
constexpr int kWarmup = 5;

struct CommandResult {
  int exit_code = -1;
  std::string output;  // stdout and stderr
};

// The tiny sequence as a bag, and a --models folder the nodelets load quickly (test/support/tiny_models.h).
class BenchCommand : public ::testing::Test {
 protected:
  void SetUp() override {
    test::TinySequence seq;
    seq.write(tmp_.path(), "0000", kClouds, /*with_labels=*/true);
    ASSERT_EQ(convertKittiToBag(tmp_.path(), bag()), static_cast<std::size_t>(kClouds));
    test::writeTinyModels(tmp_.path(), RET3D_SOURCE_DIR);
  }

  // `ret3d bench` with this test's models and the given arguments; stopped after 120 s.
  CommandResult bench(const std::vector<std::string>& args) {
    std::vector<std::string> command = {RET3D_CLI, "bench", "--models", tmp_.path(), "--detector-config",
                                        tmp_ / "detector.yaml", "--threads", "1"};
    command.insert(command.end(), args.begin(), args.end());
    const std::string log = tmp_ / ("bench" + std::to_string(++runs_) + ".log");
    CommandResult r;
    r.exit_code = test::runLogged(command, log, 120.0);
    std::ifstream in(log);
    std::stringstream ss;
    ss << in.rdbuf();
    r.output = ss.str();
    return r;
  }

  std::string bag() const { return tmp_ / "tiny.bag"; }
  test::TempDir tmp_;
  int runs_ = 0;
};

TEST_F(BenchCommand, BagThroughTheNodeletsReportsEveryStageEndToEndAndCpu) {
  const std::string json = tmp_ / "bench.json";
  // Rate 0.5: 5 clouds a second leave the untrained pipeline room on a busy 2-core machine.
  const CommandResult r = bench({"--bag", bag(), "--rate", "0.5", "--warmup", std::to_string(kWarmup), "--json", json});
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_NE(r.output.find("private ROS master"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("ret3d/InterRMNodelet"), std::string::npos) << r.output;
  ASSERT_TRUE(std::filesystem::exists(json)) << r.output;

  const YAML::Node j = YAML::LoadFile(json);
  // Every stage of the default pipeline, the input (stamp to the manager) and the end-to-end latency.
  for (const char* key : {"input", "base", "intra", "track", "inter", "end_to_end"}) {
    ASSERT_TRUE(j[key] && j[key].IsMap()) << key << " missing\n" << r.output;
    const double p50 = j[key]["median_ms"].as<double>(), p95 = j[key]["p95_ms"].as<double>();
    EXPECT_GT(p50, 0.0) << key;
    EXPECT_GE(p95, p50) << key;
  }
  // Beside each stage's input-to-output time, its own processing time from /diagnostics.
  for (const char* key : {"base", "intra", "track", "inter"})
    EXPECT_TRUE(j[key]["processing_median_ms"] && j[key]["processing_p95_ms"]) << key << "\n" << r.output;
  EXPECT_GT(j["base"]["processing_median_ms"].as<double>(), 0.0) << r.output;
  // The latency from the cloud's stamp includes every stage on the way.
  EXPECT_GT(j["end_to_end"]["median_ms"].as<double>(), j["base"]["median_ms"].as<double>()) << r.output;
  // Every cloud after the warm-up is measured; each has /objects or counts as dropped.
  const int frames = j["frames"].as<int>(), out = j["frames_out"].as<int>(), dropped = j["dropped"].as<int>();
  EXPECT_EQ(frames, kClouds - kWarmup) << r.output;
  EXPECT_EQ(out + dropped, frames);
  EXPECT_GT(out, 0) << r.output;
  EXPECT_EQ(j["end_to_end"]["frames_out"].as<int>(), out);
  EXPECT_GT(j["cpu_cores"].as<double>(), 0.0) << r.output;
  EXPECT_LE(j["cpu_cores"].as<double>(), j["cores"].as<double>() + 0.5) << r.output;
  EXPECT_NEAR(j["input_rate_hz"].as<double>(), 5.0, 0.1);
}

TEST_F(BenchCommand, WithoutRelationStagesTheTrackerReadsTheDetections) {
  const std::string json = tmp_ / "bench.json";
  const CommandResult r = bench({"--bag", bag(), "--stages", "base,track", "--rate", "0.5", "--no-markers", "--json", json});
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const YAML::Node j = YAML::LoadFile(json);
  EXPECT_TRUE(j["base"] && j["track"] && j["end_to_end"]) << r.output;
  EXPECT_FALSE(j["intra"] || j["inter"]) << r.output;
  EXPECT_GT(j["frames_out"].as<int>(), 0) << r.output;
  EXPECT_NE(r.output.find("stamp to /tracked"), std::string::npos) << r.output;
}

TEST_F(BenchCommand, GridExtentWidensTheDetectorsGroundAndAWrongOneIsAClearError) {
  // In process over the tiny sequence: the +-24 m model timed on a 96 x 48 m grid.
  const CommandResult wide =
      bench({"--data", tmp_.path(), "--stages", "base", "--warmup", "1", "--min-runs", "3", "--grid-extent=-48,48,-24,24"});
  ASSERT_EQ(wide.exit_code, 0) << wide.output;
  EXPECT_NE(wide.output.find("grid x [-48, 48] y [-24, 24]"), std::string::npos) << wide.output;
  // 60 m is not a whole number of the network's coarsest cells (8 m here).
  const CommandResult odd = bench({"--data", tmp_.path(), "--stages", "base", "--grid-extent=-30,30,-24,24"});
  EXPECT_NE(odd.exit_code, 0);
  EXPECT_NE(odd.output.find("--grid-extent: "), std::string::npos) << odd.output;
  EXPECT_NE(odd.output.find("divisible"), std::string::npos) << odd.output;
}

TEST_F(BenchCommand, MissingBagOrModelIsAClearError) {
  const CommandResult no_bag = bench({"--bag", tmp_ / "missing.bag"});
  EXPECT_NE(no_bag.exit_code, 0);
  EXPECT_NE(no_bag.output.find("missing.bag: no such file"), std::string::npos) << no_bag.output;

  const CommandResult no_model = bench({"--bag", bag(), "--inter-model", tmp_ / "none.pt"});
  EXPECT_NE(no_model.exit_code, 0);
  EXPECT_NE(no_model.output.find("none.pt: no such model file"), std::string::npos) << no_model.output;

  // Fewer clouds than the warm-up leaves nothing to measure.
  const CommandResult short_bag = bench({"--bag", bag(), "--warmup", "20"});
  EXPECT_NE(short_bag.exit_code, 0);
  EXPECT_NE(short_bag.output.find("warm-up"), std::string::npos) << short_bag.output;
}

TEST_F(BenchCommand, SoakLoopsTheBagAndSamplesMemoryDescriptorsAndLatencyPerWindow) {
  const std::string json = tmp_ / "soak/soak.json";
  // 30 clouds from a bag of 12: the loop plays it two and a half times, the stamps always increasing.
  const CommandResult r = bench({"--bag", bag(), "--rate", "0.5", "--warmup", "2", "--loop-frames", "30",
                                 "--soak-every", "10", "--json", json});
  ASSERT_EQ(r.exit_code, 0) << r.output;
  ASSERT_TRUE(std::filesystem::exists(json)) << r.output;
  EXPECT_TRUE(std::filesystem::exists(tmp_ / "soak/soak.tsv")) << r.output;
  const YAML::Node j = YAML::LoadFile(json);
  EXPECT_EQ(j["frames"].as<int>(), 30) << r.output;
  const YAML::Node samples = j["samples"];
  ASSERT_EQ(samples.size(), 4u) << r.output;  // before the first cloud, then every 10 clouds
  int measured = 0;
  for (std::size_t i = 0; i < samples.size(); ++i) {
    EXPECT_EQ(samples[i]["frame"].as<int>(), static_cast<int>(10 * i));
    EXPECT_GT(samples[i]["rss_mb"].as<double>(), 10.0);  // libtorch and the models are resident
    EXPECT_GT(samples[i]["fds"].as<int>(), 2);
    EXPECT_GT(samples[i]["threads"].as<int>(), 1);
    if (i == 0) continue;
    measured += samples[i]["measured"].as<int>();
    EXPECT_LE(samples[i]["answered"].as<int>(), samples[i]["measured"].as<int>());
    EXPECT_GE(samples[i]["end_to_end_p95_ms"].as<double>(), samples[i]["end_to_end_p50_ms"].as<double>());
  }
  // Every cloud played is in exactly one window; the warm-up's are left out of the latencies.
  EXPECT_EQ(measured, 30 - 2) << r.output;
  EXPECT_EQ(j["measured"].as<int>(), measured);
  // A 30-frame run: the reference frame is half the run in whole windows.
  ASSERT_TRUE(j["checks"]) << r.output;
  EXPECT_EQ(j["checks"]["reference_frame"].as<int>(), 10);
  EXPECT_NE(r.output.find("soak check: resident memory frame 10 -> 30"), std::string::npos) << r.output;
}

TEST_F(BenchCommand, BaselineInProcessTimesBothPipelinesAndPrintsTheRatio) {
  const std::string json = tmp_ / "bench.json";
  // The same models as their own baseline, under one busy process: the ratio's plumbing, not its value.
  const CommandResult r = bench({"--data", tmp_.path(), "--stages", "base", "--warmup", "1", "--min-runs", "3",
                                 "--baseline", tmp_.path(), "--baseline-detector-config", tmp_ / "detector.yaml",
                                 "--load", "1", "--json", json});
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_NE(r.output.find("1 busy processes spinning (--load)"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("new / baseline, interleaved frame by frame"), std::string::npos) << r.output;
  const YAML::Node j = YAML::LoadFile(json);
  EXPECT_GT(j["baseline_base"]["median_ms"].as<double>(), 0.0) << r.output;
  EXPECT_GT(j["base_ratio_median"].as<double>(), 0.0) << r.output;
  EXPECT_GT(j["base_ratio_p95"].as<double>(), 0.0) << r.output;
}

TEST_F(BenchCommand, SoakLoadAndBaselineOptionsAreCheckedBeforeAnyRun) {
  struct Case {
    std::vector<std::string> args;
    std::string message;
  };
  const std::vector<Case> cases = {
      {{"--data", tmp_.path(), "--loop-frames", "100"}, "--loop-frames (the soak) plays a bag through the nodelets"},
      {{"--bag", bag(), "--in-process", "--loop-frames", "100"}, "--loop-frames (the soak) plays a bag"},
      {{"--bag", bag(), "--loop-frames", "-3"}, "--loop-frames must be >= 0"},
      {{"--bag", bag(), "--loop-frames", "100", "--soak-every", "0"}, "--soak-every must be > 0"},
      {{"--bag", bag(), "--load", "-1"}, "--load must be >= 0"},
      {{"--bag", bag(), "--baseline", tmp_ / "nowhere"}, "nowhere: no such folder"},
      {{"--bag", bag(), "--baseline", tmp_.path(), "--loop-frames", "100"}, "--baseline and --loop-frames"},
      {{"--stages", "track", "--baseline", tmp_.path()}, "--baseline compares detectors"},
  };
  for (const Case& c : cases) {
    const CommandResult r = bench(c.args);
    EXPECT_NE(r.exit_code, 0) << c.message;
    EXPECT_NE(r.output.find(c.message), std::string::npos) << "expected: " << c.message << "\n" << r.output;
    EXPECT_EQ(r.output.find("private ROS master"), std::string::npos) << "started a run: " << r.output;
  }
  // A folder without a detector is no baseline.
  std::filesystem::create_directories(tmp_ / "empty");
  const CommandResult r = bench({"--data", tmp_.path(), "--stages", "base", "--baseline", tmp_ / "empty"});
  EXPECT_NE(r.exit_code, 0);
  EXPECT_NE(r.output.find("no detector.pt there"), std::string::npos) << r.output;
}

}  // namespace
}  // namespace ret3d
