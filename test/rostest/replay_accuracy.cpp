// rostest (test/rostest/replay_accuracy.test, node `replay_accuracy`): the bag-replay harness with the default trained
// models. It simulates a short urban drive with the real simulator (`ret3d sim ... --bag`, a seed never used
// for training or selection), replays it through the real `roslaunch ret3d replay.launch` (all five nodelets in one
// manager, rosbag play --clock with use_sim_time, the launch's default models models/lwd3d/*.pt) and checks what was
// recorded against the simulator's bag: - an /objects message for every input cloud, drops at most 1 %; no output
// twice, none for a stamp never played; - every output keeps its cloud's stamp and frame id; - accuracy: `ret3d eval
// --gt SIM.bag --pred OUT.bag` (the command a user runs) gives a mean KITTI 3D AP R40 moderate over Car, Pedestrian and
// Cyclist above kMinMeanAp; - track ids: at least 90 % of the matched ground-truth track-frames carry their track's
// most frequent output id (eval::evaluateIdStability: Hungarian on centre distance, < 2 m, per class). The figures are
// printed and recorded as test properties. test/rostest/replay.test checks the plumbing alone, quickly.
// RET3D_REPLAY_DETECTOR_MODEL=FILE replays with another detector model (the launch's detector_model), e.g. to see the
// accuracy check fail for an untrained one.
#include <gtest/gtest.h>
#include <ros/ros.h>
#include <rosbag/bag.h>
#include <rosbag/view.h>
#include <sensor_msgs/PointCloud2.h>
#include <yaml-cpp/yaml.h>

#include <chrono>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <iostream>
#include <map>
#include <sstream>

#include "support/ros_test_util.h"

#include "ret3d/eval/id_stability.h"
#include "ret3d/ros/bag_objects.h"
#include "support/test_util.h"

namespace ret3d {
namespace {

namespace fs = std::filesystem;

// 100 scans (10 s of driving): 1 % of them may be dropped, i.e. one. Seed 4242: not among the training (1000-1031,
// 2000-2007, 3000-3011), selection (5000-5001) or held-out (9000-9004) seeds, nor the demo's 777.
constexpr int kFrames = 100;
constexpr int kSeed = 4242;
// A quarter of real time: 2.5 scans a second leave the pipeline room to keep up on a busy 2-core CI machine. This test
// checks what the pipeline outputs, not its speed (`ret3d bench` measures that): at half real time a fresh-clone run
// dropped 3 of 100 scans while the hypervisor took 20-26 % of the CPU and the detector ran 4-6 times slower than idle.
constexpr double kRate = 0.25;
// Mean 3D AP R40 moderate over the three classes (KITTI devkit rules, front camera view; the figure the model card
// selects heads by). On this drive, with the simulator of car paints of every colour, queues and roadside structures,
// the default models score 27.5 (Car 17.4, Pedestrian 48.5, Cyclist 16.5: most of its cars are parked dark ones), the
// previous default detector 29.5; an untrained detector scores 0.0. One drive is a small sample (on the fresh
// held-out set of docs/RESULTS.md, 300 frames, the same models score 58.0 / 57.7 / 70.0): the bound, about two thirds
// of today's figure, tells a working pipeline from a broken one, not one model from another.
constexpr double kMinMeanAp = 18.0;
// Percent of matched ground-truth track-frames. The pipeline's tracker (config/tracker_lwd3d_pipeline.yaml:
// birth 0.3, pedestrian gate 0.8 m, max_age 10) gives 95.1 % on this drive with the models of that time (95.2 % and
// 94.9-96.2 % with two earlier generations of them); the earlier birth 0.05 / gate 0.4 m measured 85.5 % (Car 91.4, Pedestrian 76.9, Cyclist
// 95.7): one object alternating between two output tracks, pedestrians re-born outside their gate.
constexpr double kMinIdStability = 90.0;
// The stability figure must speak for a fair share of the ground truth: the default models match 55.0 % of the
// ground-truth track-frames of this drive (360 degrees, every range the simulator labels).
constexpr double kMinIdCoverage = 30.0;

using test::readText;

// The built `ret3d` command: devel/bin beside this node's devel/lib/ret3d, else whatever PATH finds.
std::string cliPath() {
  std::error_code ec;
  const fs::path self = fs::read_symlink("/proc/self/exe", ec);
  if (!ec) {
    const fs::path cli = self.parent_path().parent_path().parent_path() / "bin" / "ret3d";
    if (fs::is_regular_file(cli, ec)) return cli.string();
  }
  return "ret3d";
}

struct Cloud {
  double stamp = 0;
  std::string frame_id;
};

std::vector<Cloud> readClouds(const std::string& bag_path) {
  rosbag::Bag bag(bag_path, rosbag::bagmode::Read);
  std::vector<Cloud> out;
  for (const rosbag::MessageInstance& m : rosbag::View(bag, rosbag::TopicQuery("/points"))) {
    if (const auto msg = m.instantiate<sensor_msgs::PointCloud2>()) {
      out.push_back({msg->header.stamp.toSec(), msg->header.frame_id});
    }
  }
  return out;
}

void report(const std::string& key, double value) {
  std::cout << "replay_accuracy: " << key << " = " << value << std::endl;
  testing::Test::RecordProperty(key, std::to_string(value));
}

TEST(ReplayAccuracy, DefaultModelsOnASimulatedDrive) {
  const auto t0 = std::chrono::steady_clock::now();
  const char* package = std::getenv("RET3D_PACKAGE_DIR");
  ASSERT_NE(package, nullptr) << "RET3D_PACKAGE_DIR not set (test/rostest/replay_accuracy.test sets it)";
  test::TempDir tmp;
  const std::string cli = cliPath();

  // The drive.
  const std::string sim_log = tmp / "sim.log";
  const int sim_rc = test::runLogged({cli, "sim", "--config", std::string(package) + "/config/sim/urban_street.yaml",
                                      "--out", tmp / "sim", "--sequences", "1", "--frames", std::to_string(kFrames),
                                      "--seed", std::to_string(kSeed), "--bag"},
                                     sim_log, 150.0);
  ASSERT_EQ(sim_rc, 0) << cli << " sim failed:\n" << readText(sim_log);
  const std::string input = tmp / "sim/0000.bag";
  const std::vector<Cloud> clouds = readClouds(input);
  ASSERT_EQ(clouds.size(), static_cast<std::size_t>(kFrames)) << readText(sim_log);
  const std::vector<StampedObjects> truth = readBagObjects(input, "/ground_truth/objects");
  ASSERT_EQ(truth.size(), clouds.size());

  // The replay, with the launch's default models.
  const std::string out = tmp / "out.bag";
  const std::string launch_log = tmp / "roslaunch.log";
  std::vector<std::string> launch = {"roslaunch", "--wait", "ret3d", "replay.launch", "bag:=" + input,
                                     "record:=" + out, "rviz:=false", "rate:=" + std::to_string(kRate),
                                     "delay:=8", "tail:=4"};
  if (const char* model = std::getenv("RET3D_REPLAY_DETECTOR_MODEL")) {
    launch.push_back(std::string("detector_model:=") + model);
  }
  const double play_seconds = kFrames / 10.0 / kRate;
  const int rc = test::runLogged(launch, launch_log, 90.0 + play_seconds);
  ASSERT_EQ(rc, 0) << readText(launch_log);
  ASSERT_TRUE(fs::exists(out)) << readText(launch_log);
  const std::vector<StampedObjects> objects = readBagObjects(out, "/objects");

  // Every cloud answered (drops at most 1 %), once, with its stamp and frame id.
  std::map<double, std::string> frame_of;
  for (const Cloud& c : clouds) frame_of[c.stamp] = c.frame_id;
  std::map<double, const StampedObjects*> output_of;
  for (const StampedObjects& o : objects) {
    const auto it = frame_of.find(o.stamp);
    ASSERT_NE(it, frame_of.end()) << "output stamp " << std::fixed << o.stamp << " is no input cloud's";
    EXPECT_EQ(o.frame_id, it->second) << "frame id of the output at " << std::fixed << o.stamp;
    EXPECT_TRUE(output_of.emplace(o.stamp, &o).second) << "two outputs for the cloud at " << std::fixed << o.stamp;
  }
  const std::size_t dropped = clouds.size() - output_of.size();
  report("frames", static_cast<double>(clouds.size()));
  report("dropped", static_cast<double>(dropped));
  EXPECT_LE(dropped * 100, clouds.size()) << dropped << " of " << clouds.size() << " clouds without /objects\n"
                                          << readText(launch_log);

  // Accuracy, by the command a user runs on the recorded bag.
  const std::string eval_log = tmp / "eval.log";
  const int eval_rc = test::runLogged({cli, "eval", "--gt", input, "--pred", out, "--out", tmp / "report", "--metric",
                                       "kitti"},
                                      eval_log, 120.0);
  ASSERT_EQ(eval_rc, 0) << readText(eval_log);
  const YAML::Node metrics = YAML::LoadFile(tmp / "report/metrics.json");  // JSON is YAML
  double mean_ap = 0;
  for (const char* cls : {"Car", "Pedestrian", "Cyclist"}) {
    const std::string key = std::string("kitti.") + cls + ".3d.R40.moderate";
    ASSERT_TRUE(metrics[key]) << key << " missing from metrics.json:\n" << readText(eval_log);
    const double ap = metrics[key].as<double>();
    report(std::string("ap3d_r40_moderate_") + cls, ap);
    mean_ap += ap / 3;
  }
  report("ap3d_r40_moderate_mean", mean_ap);
  EXPECT_GE(mean_ap, kMinMeanAp) << "mean 3D AP R40 moderate over Car, Pedestrian, Cyclist\n" << readText(eval_log);

  // Track-id stability over the ground truth's track-frames.
  std::vector<eval::EvalFrame> frames;
  for (const StampedObjects& t : truth) {
    eval::EvalFrame f;
    f.frame = static_cast<int>(frames.size());
    f.stamp = t.stamp;
    f.gt_boxes = t.boxes;
    if (const auto it = output_of.find(t.stamp); it != output_of.end()) f.pred_boxes = it->second->boxes;
    frames.push_back(std::move(f));
  }
  const eval::IdStabilityResult ids = eval::evaluateIdStability(frames);
  std::ostringstream per_class;
  per_class << std::fixed << std::setprecision(1);
  for (const auto& c : ids.classes) {
    report(std::string("id_stability_") + className(c.cls), c.counts.stability());
    report(std::string("id_coverage_") + className(c.cls), c.counts.coverage());
    const eval::IdStabilityCounts& n = c.counts;
    per_class << "\n  " << className(c.cls) << ": " << n.stability() << " % stable, " << n.stable << " of "
              << n.matched << " matched (" << n.coverage() << " % of " << n.gt_track_frames
              << " ground-truth track-frames), " << n.gt_tracks << " ground-truth tracks, " << n.output_ids
              << " output ids";
  }
  report("id_stability", ids.all.stability());
  report("id_coverage", ids.all.coverage());
  report("id_matched_track_frames", static_cast<double>(ids.all.matched));
  report("id_gt_tracks", static_cast<double>(ids.all.gt_tracks));
  report("id_output_ids", static_cast<double>(ids.all.output_ids));
  EXPECT_GE(ids.all.coverage(), kMinIdCoverage)
      << ids.all.matched << " of " << ids.all.gt_track_frames << " ground-truth track-frames matched";
  EXPECT_GE(ids.all.stability(), kMinIdStability)
      << ids.all.stable << " of " << ids.all.matched << " matched ground-truth track-frames under their track's id"
      << per_class.str();
  report("seconds", std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count());
}

}  // namespace
}  // namespace ret3d
