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

#include "nodes/pipeline_test_util.h"
#include "ret3d/ros/kitti_bag.h"
#include "ros/tiny_models.h"
#include "ros/tiny_sequence.h"
#include "test_util.h"

namespace ret3d {
namespace {

constexpr int kClouds = 12;
constexpr int kWarmup = 5;

struct CommandResult {
  int exit_code = -1;
  std::string output;  // stdout and stderr
};

// The tiny sequence as a bag, and a --models folder the nodelets load quickly (test/ros/tiny_models.h).
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

}  // namespace
}  // namespace ret3d
