// Another detector's boxes through the relation stages and the tracker (`ret3d detect --detections DIR --models
// models/kitti_pointrcnn --stages ...`): every class it detects comes out of every stage combination.
#include <gtest/gtest.h>

#include <map>
#include <string>
#include <vector>

#include "ret3d/io/detections.h"
#include "ret3d/io/kitti.h"
#include "ret3d/pipeline/offline_pipeline.h"
#include "support/test_util.h"

namespace ret3d {
namespace pipeline {
namespace {

const std::string kModels = std::string(RET3D_SOURCE_DIR) + "/models/kitti_pointrcnn";
const std::vector<std::string> kCombinations = {"track",       "intra",       "inter",
                                                "intra,track", "track,inter", "intra,track,inter"};

PipelineConfig configFor(const std::string& stages) {
  PipelineConfig c;
  c.stages = parseStages(stages);
  c.models = kModels;
  c.threads = 1;
  return c;
}

Box box(ObjectClass cls, double x, double y, double length, double width, double height, double yaw, float score) {
  Box b{x, y, -0.8, length, width, height, yaw};
  b.label = cls;
  b.score = score;
  return b;
}

using ClassCounts = std::map<ObjectClass, int>;

// Twenty frames at 10 Hz, the sensor still: a car, a pedestrian and a cyclist moving, each scored as PointRCNN scores
// the objects it finds (raw logits; its true positives on KITTI tracking 0016 have medians 8.1 / 5.6 / 6.0), and
// one clutter box scored as its false positives (median 0.3).
ClassCounts runSynthetic(const std::string& stages) {
  OfflinePipeline p(configFor(stages));
  const Eigen::Isometry3d I = Eigen::Isometry3d::Identity();
  ClassCounts out;
  for (int f = 0; f < 20; ++f) {
    Detections d;
    d.boxes = {box(ObjectClass::Car, 12.0 + 1.0 * f, 3.0, 4.2, 1.7, 1.5, 0.0, 8.1f),
               box(ObjectClass::Pedestrian, 8.0, -4.0 + 0.12 * f, 0.8, 0.6, 1.75, 1.57, 5.6f),
               box(ObjectClass::Cyclist, 20.0 + 0.5 * f, -8.0, 1.8, 0.6, 1.7, 0.0, 6.0f),
               box(ObjectClass::Car, 35.0, 12.0 + 0.3 * (f % 3), 3.9, 1.6, 1.5, 0.5, 0.3f)};
    for (const Box& b : p.run(nullptr, nullptr, I, d, 0.1 * f, I).boxes)
      if (b.y < 10) ++out[b.label];  // the clutter box left out
  }
  return out;
}

TEST(ExternalDetections, EveryClassComesOutOfEveryStageCombination) {
  for (const std::string& stages : kCombinations) {
    const ClassCounts n = runSynthetic(stages);
    for (ObjectClass cls : {ObjectClass::Car, ObjectClass::Pedestrian, ObjectClass::Cyclist}) {
      // The tracker outputs a track from its second frame (birth, then a match).
      EXPECT_GE(n.count(cls) ? n.at(cls) : 0, 19) << stages << ": " << className(cls);
    }
  }
}

// The real case: PointRCNN's detections of KITTI tracking 0016 (not among the modules' training sequences 0001-0015).
// Behind IntraRM the tracker keeps at least half the boxes of each class it keeps without it (IntraRM's scores are
// probabilities that a box is right: the tracker starts a track from 0.75).
TEST(ExternalDetections, PointRcnnOnKittiKeepsEachClassBehindIntraRM) {
  const auto shared = test::sharedDataDir();
  if (!shared) GTEST_SKIP() << test::kSharedDataMissing;
  const std::string root = *shared + "/kitti_tracking", dets_dir = root + "/detections/pointrcnn", seq = "0016";
  const kitti::TrackingDataset ds(root);
  const kitti::Calibration calib = ds.calibration(seq);
  const auto poses = ds.lidarPoses(seq);
  const auto dets = io::readSequenceDetections(dets_dir, io::detectDetectionLayout(dets_dir), seq);
  ASSERT_FALSE(poses.empty());
  std::map<std::string, ClassCounts> counts;
  for (const std::string& stages : {"track", "intra,track,inter"}) {
    OfflinePipeline p(configFor(stages));
    const Eigen::Isometry3d I = Eigen::Isometry3d::Identity();
    for (int f = 0; f < static_cast<int>(poses.size()); ++f) {
      Detections d;
      if (const auto it = dets.find(f); it != dets.end())
        for (const kitti::Label& l : it->second) d.boxes.push_back(kitti::labelToBox(l, calib));
      for (const Box& b : p.run(nullptr, nullptr, I, d, 0.1 * f, poses[static_cast<std::size_t>(f)]).boxes)
        ++counts[stages][b.label];
    }
  }
  for (ObjectClass cls : {ObjectClass::Car, ObjectClass::Pedestrian, ObjectClass::Cyclist}) {
    const int alone = counts["track"][cls], behind = counts["intra,track,inter"][cls];
    EXPECT_GT(alone, 100) << className(cls);
    EXPECT_GE(2 * behind, alone) << className(cls) << ": " << behind << " boxes behind IntraRM, " << alone
                                      << " without";
  }
}

}  // namespace
}  // namespace pipeline
}  // namespace ret3d
