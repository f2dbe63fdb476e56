#include "ret3d/eval/id_stability.h"

#include <gtest/gtest.h>

#include <stdexcept>

#include "support/boxes.h"
#include "support/error_message.h"

namespace ret3d {
namespace eval {
namespace {

Box box(double x, double y, std::uint32_t id, ObjectClass cls = ObjectClass::Car) {
  Box b = test::carBox(x, y);
  b.label = cls;
  b.track_id = id;
  return b;
}

// Two ground-truth cars over n frames: A (id 1) at y = 0 and B (id 2) at y = 10, both moving along x.
std::vector<EvalFrame> groundTruth(int n = 10, const std::string& sequence = "0000") {
  std::vector<EvalFrame> frames(n);
  for (int t = 0; t < n; ++t) {
    frames[t].sequence = sequence;
    frames[t].frame = t;
    frames[t].gt_boxes = {box(t, 0, 1), box(t, 10, 2)};
    frames[t].gt_ignore = {0, 0};
  }
  return frames;
}

const IdStabilityCounts& cars(const IdStabilityResult& r) { return r.classes.at(0).counts; }

TEST(IdStability, OneIdPerObjectIsFullyStableWhateverTheIds) {
  auto frames = groundTruth();
  for (auto& f : frames) f.pred_boxes = {box(f.frame + 0.5, 0.3, 7), box(f.frame, 10.4, 8)};
  const IdStabilityResult r = evaluateIdStability(frames);
  ASSERT_EQ(r.classes.size(), 3u);
  EXPECT_EQ(cars(r).gt_track_frames, 20u);
  EXPECT_EQ(cars(r).matched, 20u);
  EXPECT_EQ(cars(r).stable, 20u);
  EXPECT_EQ(cars(r).gt_tracks, 2u);
  EXPECT_EQ(cars(r).output_ids, 2u);
  EXPECT_DOUBLE_EQ(r.all.stability(), 100.0);
  EXPECT_DOUBLE_EQ(r.all.coverage(), 100.0);
}

TEST(IdStability, AnIdSwitchCostsTheFramesUnderTheMinorityId) {
  auto frames = groundTruth();
  // A is followed by id 7 for six frames, then by id 9; B keeps id 8.
  for (auto& f : frames) f.pred_boxes = {box(f.frame, 0, f.frame < 6 ? 7 : 9), box(f.frame, 10, 8)};
  const IdStabilityResult r = evaluateIdStability(frames);
  EXPECT_EQ(cars(r).matched, 20u);
  EXPECT_EQ(cars(r).stable, 16u);
  EXPECT_DOUBLE_EQ(r.all.stability(), 80.0);
  EXPECT_EQ(cars(r).output_ids, 3u);
}

TEST(IdStability, MissedFramesLowerCoverageNotStability) {
  auto frames = groundTruth();
  // Only A, and only in every other frame, always with the same id.
  for (auto& f : frames) {
    if (f.frame % 2 == 0) f.pred_boxes = {box(f.frame, 0, 7)};
  }
  const IdStabilityResult r = evaluateIdStability(frames);
  EXPECT_EQ(cars(r).matched, 5u);
  EXPECT_EQ(cars(r).gt_tracks, 1u);
  EXPECT_DOUBLE_EQ(r.all.stability(), 100.0);
  EXPECT_DOUBLE_EQ(r.all.coverage(), 25.0);
}

TEST(IdStability, OnlyCloseBoxesOfTheSameClassMatch) {
  auto frames = groundTruth();
  for (auto& f : frames) {
    // 2.5 m off, and a pedestrian right on B: neither covers a car.
    f.pred_boxes = {box(f.frame + 2.5, 0, 7), box(f.frame, 10, 8, ObjectClass::Pedestrian)};
  }
  const IdStabilityResult r = evaluateIdStability(frames);
  EXPECT_EQ(r.all.matched, 0u);
  EXPECT_DOUBLE_EQ(r.all.stability(), 0.0);
  EXPECT_EQ(r.all.gt_track_frames, 20u);

  IdStabilityOptions wide;
  wide.max_center_distance = 3.0;
  EXPECT_EQ(evaluateIdStability(frames, wide).all.matched, 10u);
}

TEST(IdStability, OptimalAssignmentMatchesWhereGreedyNearestWouldNot) {
  // A at x = 0 and B at x = 1.5; outputs P at 0.8 (nearest to B) and Q at 2.6 (2.6 m from A, 1.1 m from B).
  // Greedy by distance pairs B-P and leaves A without a match within 2 m; the optimal assignment pairs A-P and B-Q.
  std::vector<EvalFrame> frames(4);
  for (int t = 0; t < 4; ++t) {
    frames[t].frame = t;
    frames[t].gt_boxes = {box(0, 0, 1), box(1.5, 0, 2)};
    frames[t].pred_boxes = {box(0.8, 0, 7), box(2.6, 0, 8)};
  }
  const IdStabilityResult r = evaluateIdStability(frames);
  EXPECT_EQ(cars(r).matched, 8u);
  EXPECT_EQ(cars(r).stable, 8u);
  EXPECT_EQ(cars(r).gt_tracks, 2u);
}

TEST(IdStability, OutputsWithoutIdsAreMatchedButNeverStable) {
  auto frames = groundTruth(4);
  for (auto& f : frames) f.pred_boxes = {box(f.frame, 0, 0), box(f.frame, 10, f.frame == 0 ? 0 : 5)};
  const IdStabilityResult r = evaluateIdStability(frames);
  EXPECT_EQ(cars(r).matched, 8u);
  EXPECT_EQ(cars(r).stable, 3u);  // B under id 5 in frames 1-3
  EXPECT_EQ(cars(r).output_ids, 1u);
}

TEST(IdStability, IgnoredGroundTruthTakesNoPart) {
  auto frames = groundTruth(4);
  for (auto& f : frames) {
    f.gt_ignore = {0, 1};                                          // B is a Van, say
    f.pred_boxes = {box(f.frame, 0, 7), box(f.frame, 10, f.frame)};  // a new id on B every frame
  }
  const IdStabilityResult r = evaluateIdStability(frames);
  EXPECT_EQ(cars(r).gt_track_frames, 4u);
  EXPECT_EQ(cars(r).matched, 4u);
  EXPECT_DOUBLE_EQ(r.all.stability(), 100.0);
}

TEST(IdStability, IdsArePerSequenceAndClassesPoolByTrackFrames) {
  auto frames = groundTruth(4, "0000");
  for (auto& f : groundTruth(4, "0001")) frames.push_back(f);
  // The same output id 7 on A in both sequences: two tracks, each stable.
  for (auto& f : frames) f.pred_boxes = {box(f.frame, 0, 7)};
  // And a pedestrian, id 3, covered by id 4 then id 5 (one frame each) in sequence 0000.
  frames[0].gt_boxes.push_back(box(20, 0, 3, ObjectClass::Pedestrian));
  frames[0].gt_ignore.push_back(0);
  frames[0].pred_boxes.push_back(box(20, 0, 4, ObjectClass::Pedestrian));
  frames[1].gt_boxes.push_back(box(20, 0, 3, ObjectClass::Pedestrian));
  frames[1].gt_ignore.push_back(0);
  frames[1].pred_boxes.push_back(box(20, 0, 5, ObjectClass::Pedestrian));
  const IdStabilityResult r = evaluateIdStability(frames);
  EXPECT_EQ(cars(r).gt_tracks, 2u);
  EXPECT_EQ(cars(r).output_ids, 2u);
  EXPECT_EQ(cars(r).stable, 8u);
  EXPECT_EQ(r.classes.at(1).counts.matched, 2u);
  EXPECT_EQ(r.classes.at(1).counts.stable, 1u);
  EXPECT_EQ(r.all.matched, 10u);
  EXPECT_EQ(r.all.stable, 9u);
  EXPECT_DOUBLE_EQ(r.all.stability(), 90.0);
}

TEST(IdStability, GroundTruthWithoutIdIsRejected) {
  auto frames = groundTruth(2);
  frames[1].gt_boxes[0].track_id = 0;
  const std::string msg = test::errorMessage<std::invalid_argument>([&] { evaluateIdStability(frames); });
  EXPECT_NE(msg.find("frame 1"), std::string::npos) << msg;
  IdStabilityOptions bad;
  bad.max_center_distance = 0;
  EXPECT_THROW(evaluateIdStability(groundTruth(2), bad), std::invalid_argument);
}

}  // namespace
}  // namespace eval
}  // namespace ret3d
