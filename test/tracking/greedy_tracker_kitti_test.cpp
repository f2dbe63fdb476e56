// The tracker on real data: PointRCNN detections and stereo-SLAM ego poses of the KITTI tracking benchmark
// (../shared/data), compared with the ground-truth tracks of label_02. Skips when the data is absent. The full
// MOTA / HOTA evaluation is `ret3d eval`'s; this checks that ids behave sanely and prints ID statistics.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <map>
#include <set>
#include <string>

#include "ret3d/core/transform.h"
#include "ret3d/io/detections.h"
#include "ret3d/io/kitti.h"
#include "ret3d/tracking/greedy_tracker.h"
#include "support/test_util.h"

namespace ret3d {
namespace {

constexpr double kFramePeriod = 0.1;  // KITTI tracking: 10 Hz

struct Sequence {
  std::vector<Eigen::Isometry3d> poses;             // T_velo0_velo_t: sensor_to_fixed per frame
  std::map<int, std::vector<Box>> detections;       // LiDAR frame
  std::map<int, std::vector<Box>> truth;            // LiDAR frame, track_id = ground-truth id + 1
};

Sequence loadSequence(const std::string& data, const std::string& seq) {
  const kitti::TrackingDataset ds(data + "/kitti_tracking");
  const kitti::Calibration calib = kitti::readCalibration(ds.calibPath(seq));
  Sequence s;
  s.poses = ds.lidarPoses(seq);
  const std::string det_dir = data + "/kitti_tracking/detections/pointrcnn";
  for (const auto& [frame, labels] : io::readSequenceDetections(det_dir, io::DetectionLayout::PerClassCsv, seq)) {
    for (const kitti::Label& l : labels) {
      Box b = kitti::labelToBox(l, calib);
      // PointRCNN's scores are logits; the tracker's thresholds are probabilities.
      b.score = static_cast<float>(1.0 / (1.0 + std::exp(-static_cast<double>(b.score))));
      s.detections[frame].push_back(b);
    }
  }
  for (const kitti::Label& l : kitti::readTrackingLabels(ds.labelPath(seq))) {
    if (l.track_id < 0 || !classFromName(l.type)) continue;  // DontCare, Van, Truck, Person_sitting, ...
    Box b = kitti::labelToBox(l, calib);
    b.track_id = static_cast<std::uint32_t>(l.track_id) + 1;
    s.truth[l.frame].push_back(b);
  }
  return s;
}

struct ClassStats {
  std::set<std::uint32_t> truth_ids, track_ids;
  std::set<std::uint32_t> paired_track_ids;  // tracker ids ever paired with a truth box
  int short_tracks = 0;                       // tracker ids output in fewer than 3 frames
  int truth_boxes = 0, matched = 0, id_switches = 0;
};

// Runs the tracker over a sequence and compares with the truth: per frame, each ground-truth box is paired with the
// nearest unpaired output of its class within 2 m (cars) or 1 m (others); an ID switch is a ground-truth track paired
// with a different tracker id than the last time it was paired (CLEAR MOT's definition).
std::map<ObjectClass, ClassStats> track(const Sequence& s, const TrackerOptions& o, bool use_poses) {
  GreedyTracker tracker(o);
  std::map<ObjectClass, ClassStats> stats;
  std::map<std::uint32_t, std::uint32_t> last_pair;  // truth id -> tracker id
  std::map<std::uint32_t, int> frames_out;            // tracker id -> frames output
  for (int f = 0; f < static_cast<int>(s.poses.size()); ++f) {
    const auto dit = s.detections.find(f);
    const std::vector<Box> dets = dit == s.detections.end() ? std::vector<Box>() : dit->second;
    const Eigen::Isometry3d pose = use_poses ? s.poses[f] : Eigen::Isometry3d::Identity();
    const std::vector<Box> out = tracker.update(dets, f * kFramePeriod, pose);
    for (const Box& b : out) {
      stats[b.label].track_ids.insert(b.track_id);
      ++frames_out[b.track_id];
    }
    const auto tit = s.truth.find(f);
    if (tit == s.truth.end()) continue;
    std::vector<char> used(out.size(), 0);
    for (const Box& g : tit->second) {
      ClassStats& cs = stats[g.label];
      cs.truth_ids.insert(g.track_id);
      ++cs.truth_boxes;
      const double gate = g.label == ObjectClass::Car ? 2.0 : 1.0;
      int best = -1;
      double best_d = gate;
      for (std::size_t k = 0; k < out.size(); ++k) {
        if (used[k] || out[k].label != g.label) continue;
        const double d = std::hypot(out[k].x - g.x, out[k].y - g.y);
        if (d < best_d) {
          best_d = d;
          best = static_cast<int>(k);
        }
      }
      if (best < 0) continue;
      used[best] = 1;
      ++cs.matched;
      cs.paired_track_ids.insert(out[best].track_id);
      auto it = last_pair.find(g.track_id);
      if (it != last_pair.end() && it->second != out[best].track_id) ++cs.id_switches;
      last_pair[g.track_id] = out[best].track_id;
    }
  }
  for (auto& [c, cs] : stats)
    for (std::uint32_t id : cs.track_ids) cs.short_tracks += frames_out[id] < 3;
  return stats;
}

void print(const std::string& what, const std::map<ObjectClass, ClassStats>& stats) {
  for (const auto& [c, s] : stats) {
    if (s.truth_ids.empty()) continue;
    std::printf("[ kitti    ] %-34s %-10s truth tracks %3zu, tracker ids %4zu, truth boxes %5d, paired %5.1f%%, "
                "ID switches %3d (%.1f per 100 truth tracks); tracker ids paired with truth %4zu, output < 3 frames %4d\n",
                what.c_str(), className(c), s.truth_ids.size(), s.track_ids.size(), s.truth_boxes,
                100.0 * s.matched / std::max(1, s.truth_boxes), s.id_switches,
                100.0 * s.id_switches / static_cast<double>(s.truth_ids.size()), s.paired_track_ids.size(),
                s.short_tracks);
  }
}

TEST(GreedyTrackerKitti, PointRcnnSequence0001HasSaneIds) {
  const auto data = test::sharedDataDir();
  if (!data) GTEST_SKIP() << test::kSharedDataMissing;
  const Sequence s = loadSequence(*data, "0001");
  ASSERT_EQ(s.poses.size(), 447u);
  ASSERT_FALSE(s.detections.empty());
  // The ego drives: the check is meaningful only if it moves well beyond the gates.
  EXPECT_GT((s.poses.back().translation() - s.poses.front().translation()).norm(), 50.0);

  const auto stats = track(s, TrackerOptions(), true);
  print("0001, defaults", stats);
  const ClassStats& car = stats.at(ObjectClass::Car);
  ASSERT_GT(car.truth_ids.size(), 50u);
  EXPECT_GT(car.matched, car.truth_boxes * 8 / 10);
  for (const auto& [c, cs] : stats) {
    if (cs.truth_ids.empty()) continue;
    // Each truth track is covered by few tracker ids, and few of its frames switch ids.
    EXPECT_LE(cs.paired_track_ids.size(), 2 * cs.truth_ids.size() + 2) << className(c);
    EXPECT_LE(cs.id_switches, static_cast<int>(cs.truth_ids.size()) / 2 + 2) << className(c);
  }
  // All ids, false tracks from the detector's clutter included (most live under 3 frames): a small multiple.
  EXPECT_LE(car.track_ids.size(), 5 * car.truth_ids.size());

  // Without the ego poses (tracking in the moving sensor frame) ids switch more.
  const auto no_poses = track(s, TrackerOptions(), false);
  print("0001, no ego poses", no_poses);
  int switches = 0, switches_no_poses = 0;
  for (const auto& [c, cs] : stats) switches += cs.id_switches;
  for (const auto& [c, cs] : no_poses) switches_no_poses += cs.id_switches;
  EXPECT_GT(switches_no_poses, switches);
}

// The ablation behind the defaults of config/tracker.yaml: ID switches and ids per truth track over the training
// sequences 0001-0015 for gates, max_age and the matcher. Prints only.
TEST(GreedyTrackerKitti, AblationOverTrainingSequences) {
  const auto data = test::sharedDataDir();
  if (!data) GTEST_SKIP() << test::kSharedDataMissing;
  std::vector<Sequence> seqs;
  for (int i = 1; i <= 15; ++i) {
    char name[8];
    std::snprintf(name, sizeof(name), "%04d", i);
    seqs.push_back(loadSequence(*data, name));
  }
  struct Variant {
    std::string name;
    TrackerOptions o;
  };
  std::vector<Variant> variants;
  variants.push_back({"defaults", TrackerOptions()});
  auto with = [&](const std::string& n, auto edit) {
    TrackerOptions o;
    edit(o);
    variants.push_back({n, o});
  };
  with("gates 1.0/0.6/0.8", [](TrackerOptions& o) { o.gate = {1.0, 0.6, 0.8}; });
  with("gates 1.2/0.5/0.8", [](TrackerOptions& o) { o.gate = {1.2, 0.5, 0.8}; });
  with("gates 0.8/0.4/0.6 (CenterPoint Waymo)", [](TrackerOptions& o) { o.gate = {0.8, 0.4, 0.6}; });
  with("gates 1.5/0.6/1.0", [](TrackerOptions& o) { o.gate = {1.5, 0.6, 1.0}; });
  with("gates 2.0/1.0/1.5", [](TrackerOptions& o) { o.gate = {2.0, 1.0, 1.5}; });
  with("max_age 1", [](TrackerOptions& o) { o.max_age = 1; });
  with("max_age 3", [](TrackerOptions& o) { o.max_age = 3; });
  with("max_age 10", [](TrackerOptions& o) { o.max_age = 10; });
  with("hungarian", [](TrackerOptions& o) { o.assignment = AssignmentMethod::Hungarian; });
  with("velocity_window 3", [](TrackerOptions& o) { o.velocity_window = 3; });
  with("velocity_window 10", [](TrackerOptions& o) { o.velocity_window = 10; });
  with("birth_score 0.5", [](TrackerOptions& o) { o.birth_score = {0.5, 0.5, 0.5}; });
  with("birth_score 0.9", [](TrackerOptions& o) { o.birth_score = {0.9, 0.9, 0.9}; });
  with("max_speed 0 (no unknown-velocity slack)", [](TrackerOptions& o) { o.max_speed = {0, 0, 0}; });
  std::printf("[ kitti    ] %-42s | per class: ID switches (per 100 truth tracks), ids paired with truth, all ids, "
              "truth boxes paired\n", "0001-0015 ablation");
  for (const Variant& v : variants) {
    std::map<ObjectClass, ClassStats> total;
    std::uint32_t offset = 0;  // ids are per sequence: offset them so sequences do not collide
    for (const Sequence& s : seqs) {
      for (const auto& [c, cs] : track(s, v.o, true)) {
        ClassStats& t = total[c];
        t.truth_boxes += cs.truth_boxes;
        t.matched += cs.matched;
        t.id_switches += cs.id_switches;
        t.short_tracks += cs.short_tracks;
        for (std::uint32_t id : cs.truth_ids) t.truth_ids.insert(id + offset);
        for (std::uint32_t id : cs.track_ids) t.track_ids.insert(id + offset);
        for (std::uint32_t id : cs.paired_track_ids) t.paired_track_ids.insert(id + offset);
      }
      offset += 100000u;
    }
    std::string line;
    for (const auto& [c, t] : total) {
      char buf[160];
      std::snprintf(buf, sizeof(buf), " | %s %3d (%4.1f) %4zu %5zu %4.1f%%", className(c), t.id_switches,
                    100.0 * t.id_switches / std::max<std::size_t>(1, t.truth_ids.size()), t.paired_track_ids.size(),
                    t.track_ids.size(), 100.0 * t.matched / std::max(1, t.truth_boxes));
      line += buf;
    }
    std::printf("[ kitti    ] %-42s%s\n", v.name.c_str(), line.c_str());
  }
}

}  // namespace
}  // namespace ret3d
