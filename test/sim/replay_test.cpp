#include "ret3d/sim/replay.h"

#include <filesystem>
#include <map>

#include <gtest/gtest.h>

#include "ret3d/sim/simulator.h"
#include "support/test_util.h"

namespace ret3d {
namespace sim {
namespace {

namespace fs = std::filesystem;

// Replays `seq` of `root` and checks every Car, Pedestrian and Cyclist label of the output against the input
// (camera coordinates, 1 cm) and the poses (written verbatim).
void checkReplay(const std::string& root, const std::string& seq, int frames, std::size_t* compared) {
  test::TempDir out;
  SimOptions o;
  o.config = loadSimConfig(std::string(RET3D_SOURCE_DIR) + "/config/sim/urban_street.yaml");
  o.sensor = sensorByName("hdl64e", RET3D_SOURCE_DIR);
  o.out_dir = out.path();
  o.frames = frames;
  o.seed = 1;
  o.replay_dir = root;
  o.replay_sequence = seq;
  const SequenceReport r = simulateSequence(o, 0);
  kitti::TrackingDataset in(root), sim(out.path());
  const auto in_labels = kitti::readTrackingLabels(in.labelPath(seq));
  const auto out_labels = kitti::readTrackingLabels(sim.labelPath("0000"));
  std::map<std::pair<int, int>, kitti::Label> got;
  for (const auto& l : out_labels) got[{l.frame, l.track_id}] = l;
  *compared = 0;
  for (const auto& l : in_labels) {
    if (l.frame >= static_cast<int>(r.frames.size())) continue;
    if (l.type != "Car" && l.type != "Pedestrian" && l.type != "Cyclist") continue;
    auto it = got.find({l.frame, l.track_id});
    ASSERT_NE(it, got.end()) << "frame " << l.frame << " track " << l.track_id << " missing";
    const kitti::Label& g = it->second;
    EXPECT_EQ(g.type, l.type);
    EXPECT_NEAR(g.x, l.x, 0.01);
    EXPECT_NEAR(g.y, l.y, 0.01);
    EXPECT_NEAR(g.z, l.z, 0.01);
    EXPECT_NEAR(g.l, l.l, 0.01);
    EXPECT_NEAR(g.w, l.w, 0.01);
    EXPECT_NEAR(g.h, l.h, 0.01);
    EXPECT_NEAR(std::remainder(g.rotation_y - l.rotation_y, 2 * M_PI), 0.0, 0.002);
    ++*compared;
  }
  EXPECT_EQ(*compared, out_labels.size()) << "the output holds exactly the replayed tracks";
  const auto pin = in.lidarPoses(seq), pout = sim.lidarPoses("0000");
  ASSERT_EQ(pout.size(), r.frames.size());
  for (std::size_t f = 0; f < pout.size(); ++f)
    EXPECT_LT((pin[f].translation() - pout[f].translation()).norm(), 0.01) << "pose " << f;
}

TEST(Replay, ReproducesATinySequence) {
  test::TempDir root;
  for (const char* sub : {"label_02", "calib", "pose"}) fs::create_directories(root / (std::string("training/") + sub));
  const kitti::Calibration calib = kitti::defaultCalibration();
  kitti::writeCalibration(root / "training/calib/0003.txt", calib);
  // Ego drives forward (camera z) 1 m per frame while turning slightly; three actors move.
  std::vector<Eigen::Isometry3d> poses;
  std::vector<kitti::Label> labels;
  for (int f = 0; f < 6; ++f) {
    Eigen::Isometry3d P = Eigen::Isometry3d::Identity();
    P.linear() = Eigen::AngleAxisd(0.01 * f, Eigen::Vector3d::UnitY()).toRotationMatrix();
    P.translation() = Eigen::Vector3d(0.02 * f, 0, 1.0 * f);
    poses.push_back(P);
    kitti::Label car;
    car.frame = f;
    car.track_id = 0;
    car.type = "Car";
    car.h = 1.5;
    car.w = 1.7;
    car.l = 4.1;
    car.x = 3.0;
    car.y = 1.65;
    car.z = 15.0 - 0.5 * f;
    car.rotation_y = -M_PI / 2;
    labels.push_back(car);
    kitti::Label ped = car;
    ped.track_id = 4;
    ped.type = "Pedestrian";
    ped.h = 1.75;
    ped.w = 0.6;
    ped.l = 0.8;
    ped.x = -5.0 + 0.14 * f;
    ped.z = 10.0;
    ped.rotation_y = 0.0;
    labels.push_back(ped);
    if (f < 4) {  // leaves the labels after frame 3
      kitti::Label cyc = car;
      cyc.track_id = 7;
      cyc.type = "Cyclist";
      cyc.h = 1.73;
      cyc.w = 0.6;
      cyc.l = 1.76;
      cyc.x = -2.0;
      cyc.z = 20.0 + 0.5 * f;
      cyc.rotation_y = M_PI / 2;
      labels.push_back(cyc);
    }
    kitti::Label van = car;  // drawn, not labelled
    van.track_id = 9;
    van.type = "Van";
    van.x = 6.0;
    van.z = 30.0;
    labels.push_back(van);
  }
  kitti::writePoses(root / "training/pose/0003.txt", poses);
  kitti::writeTrackingLabels(root / "training/label_02/0003.txt", labels);
  std::size_t compared = 0;
  checkReplay(root.path(), "0003", 10, &compared);
  EXPECT_EQ(compared, 6u + 6u + 4u);
}

TEST(Replay, ReproducesKittiTrackingSequence0001) {
  const auto data = test::sharedDataDir();
  if (!data) GTEST_SKIP() << test::kSharedDataMissing;
  const std::string root = *data + "/kitti_tracking";
  if (!fs::exists(root + "/training/label_02/0001.txt")) GTEST_SKIP() << "kitti_tracking sequence 0001 absent";
  std::size_t compared = 0;
  checkReplay(root, "0001", 15, &compared);
  EXPECT_GT(compared, 20u);
}

}  // namespace
}  // namespace sim
}  // namespace ret3d
