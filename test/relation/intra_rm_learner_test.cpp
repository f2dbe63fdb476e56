#include "ret3d/relation/intra_rm_learner.h"

#include <array>
#include <random>

#include <gtest/gtest.h>

#include "support/intra_rm_scenes.h"
#include "support/test_util.h"

namespace ret3d {
namespace relation {
namespace {

IntraRMConfig smallConfig() {
  IntraRMConfig c;
  c.model.hidden = 32;
  c.model.head_hidden = 32;
  c.train.lr = 3e-3;
  return c;
}

TEST(IntraRMLearner, ATinyTrainingRunLowersTheLossAndMovesBoxesTowardsTheTruth) {
  std::mt19937 rng(1);
  std::vector<IntraRMFrame> train, val;
  for (int i = 0; i < 64; ++i) train.push_back(test::randomFrame(rng, 10));
  for (int i = 0; i < 16; ++i) val.push_back(test::randomFrame(rng, 10));
  IntraRMLearner learner(smallConfig(), 3);
  learner.fitNormalisation(train);
  const IntraRMLoss before = learner.evaluate(val);
  for (int epoch = 0; epoch < 6; ++epoch) {
    for (std::size_t s = 0; s < train.size(); s += 16) {
      std::vector<const IntraRMFrame*> batch;
      for (std::size_t f = s; f < s + 16; ++f) batch.push_back(&train[f]);
      learner.step(batch);
    }
  }
  const IntraRMLoss after = learner.evaluate(val);
  EXPECT_LT(after.total, 0.7 * before.total) << "before " << before.total << " after " << after.total;
  EXPECT_LT(after.reg, before.reg);
  EXPECT_LT(after.cls, before.cls);
  // The synthetic detector places boxes 0.3 m short along x: the refined boxes should be closer to the truth.
  double err_before = 0, err_after = 0;
  int n = 0;
  for (const IntraRMFrame& f : val) {
    const Detections r = learner.model().refine(f.detections);
    for (std::size_t i = 0; i < f.detections.size(); ++i) {
      const IntraRMTarget& t = f.targets[i];
      if (!t.regress) continue;
      err_before += std::hypot(t.dx, t.dy);
      err_after += std::hypot(t.dx - (r.boxes[i].x - f.detections.boxes[i].x),
                              t.dy - (r.boxes[i].y - f.detections.boxes[i].y));
      ++n;
    }
  }
  ASSERT_GT(n, 50);
  EXPECT_LT(err_after / n, 0.75 * err_before / n);
}

// The focal loss leaves the raw sigmoid below the chance that a box is right; after calibration the published score
// is that chance: over the boxes it was fitted on, the mean score equals the fraction of true positives (a property of
// the logistic fit), per class, and the calibration travels with the model file.
TEST(IntraRMLearner, CalibratedScoresAreTheChanceOfATruePositive) {
  std::mt19937 rng(2);
  std::vector<IntraRMFrame> train;
  for (int i = 0; i < 48; ++i) train.push_back(test::randomFrame(rng, 10));
  IntraRMLearner learner(smallConfig(), 3);
  learner.fitNormalisation(train);
  for (int epoch = 0; epoch < 3; ++epoch) {
    for (std::size_t s = 0; s < train.size(); s += 16) {
      std::vector<const IntraRMFrame*> batch;
      for (std::size_t f = s; f < s + 16; ++f) batch.push_back(&train[f]);
      learner.step(batch);
    }
  }
  ret3d::test::TempDir tmp;
  learner.model().save(tmp / "intra.pt");
  IntraRMOptions o;
  o.model_path = tmp / "intra.pt";
  IntraRM model(o);
  const PerClass<std::size_t> used = calibrateIntraRMScores(&model, train);
  model.save(tmp / "intra.pt");
  const IntraRM loaded(o);
  std::array<double, 3> score{}, positives{};
  for (const IntraRMFrame& f : train) {
    const Detections r = loaded.refine(f.detections);
    for (std::size_t i = 0; i < r.size(); ++i) {
      const std::size_t c = static_cast<std::size_t>(classIndex(r.boxes[i].label));
      if (f.targets[i].cls_weight <= 0) continue;
      score[c] += r.boxes[i].score;
      positives[c] += f.targets[i].cls[c];
    }
  }
  for (std::size_t c = 0; c < 3; ++c) {
    ASSERT_GT(used[c], 50u);
    EXPECT_NE(loaded.arch().score_scale[c], 1.0) << c;
    EXPECT_EQ(loaded.arch().score_scale[c], model.arch().score_scale[c]);
    EXPECT_EQ(loaded.arch().score_bias[c], model.arch().score_bias[c]);
    EXPECT_NEAR(score[c] / static_cast<double>(used[c]), positives[c] / static_cast<double>(used[c]), 0.01) << c;
  }
}

TEST(IntraRMLearner, CheckpointResumesTheSameState) {
  ret3d::test::TempDir tmp;
  std::mt19937 rng(2);
  std::vector<IntraRMFrame> frames;
  for (int i = 0; i < 16; ++i) frames.push_back(test::randomFrame(rng, 8));
  std::vector<const IntraRMFrame*> batch;
  for (const auto& f : frames) batch.push_back(&f);
  IntraRMLearner a(smallConfig(), 3);
  a.fitNormalisation(frames);
  a.step(batch);
  a.saveCheckpoint(tmp.path(), 1, 0.5);
  IntraRMLearner b(smallConfig(), 99);
  int epoch = 0;
  double best = 0;
  ASSERT_TRUE(b.loadCheckpoint(tmp.path(), &epoch, &best));
  EXPECT_EQ(epoch, 1);
  EXPECT_DOUBLE_EQ(best, 0.5);
  EXPECT_DOUBLE_EQ(a.evaluate(frames).total, b.evaluate(frames).total);
  // The next steps (optimiser moments and augmentation draws restored) agree too.
  a.step(batch);
  b.step(batch);
  EXPECT_NEAR(a.evaluate(frames).total, b.evaluate(frames).total, 1e-6);
  IntraRMLearner c(smallConfig(), 3);
  EXPECT_FALSE(c.loadCheckpoint(tmp / "nothing", &epoch, &best));
  IntraRMConfig other = smallConfig();
  other.model.rounds = 2;
  IntraRMLearner d(other, 3);
  EXPECT_THROW(d.loadCheckpoint(tmp.path(), &epoch, &best), std::runtime_error);
}

}  // namespace
}  // namespace relation
}  // namespace ret3d
