#include "ret3d/relation/intra_rm.h"

#include <algorithm>
#include <chrono>
#include <filesystem>
#include <fstream>
#include <numeric>
#include <random>

#include <gtest/gtest.h>

#include "ret3d/relation/intra_rm_learner.h"
#include "support/boxes.h"
#include "support/error_message.h"
#include "support/intra_rm_scenes.h"
#include "support/test_util.h"

namespace ret3d {
namespace relation {
namespace {

// A module with non-trivial weights: a few training steps from an untrained one (whose residual heads are zero).
const IntraRM& trainedModule(std::size_t feature_dim = 0) {
  static std::map<std::size_t, std::unique_ptr<IntraRM>> cache;
  auto& m = cache[feature_dim];
  if (!m) {
    IntraRMConfig c;
    c.model.feature_dim = feature_dim;
    c.model.hidden = 16;
    c.model.head_hidden = 16;
    c.train.lr = 1e-2;
    IntraRMLearner learner(c, 5);
    std::mt19937 rng(11);
    std::vector<IntraRMFrame> frames;
    for (int i = 0; i < 8; ++i) frames.push_back(test::randomFrame(rng, 12, feature_dim));
    learner.fitNormalisation(frames);
    std::vector<const IntraRMFrame*> batch;
    for (const auto& f : frames) batch.push_back(&f);
    for (int i = 0; i < 5; ++i) learner.step(batch);
    m = std::make_unique<IntraRM>(learner.snapshot());
  }
  return *m;
}

void expectBoxNear(const Box& a, const Box& b, double tol = 1e-4) {
  ret3d::test::expectSameCentreAndSize(a, b, tol);
  EXPECT_NEAR(a.yaw, b.yaw, tol);
  EXPECT_NEAR(a.score, b.score, tol);
  EXPECT_EQ(a.label, b.label);
}

TEST(IntraRM, UntrainedModuleKeepsTheBoxes) {
  IntraRM m(IntraRMArch{}, 1);
  std::mt19937 rng(1);
  const Detections in = test::randomFrame(rng, 10).detections;
  const Detections out = m.refine(in);
  ASSERT_EQ(out.size(), in.size());
  for (std::size_t i = 0; i < in.size(); ++i) {
    EXPECT_DOUBLE_EQ(out.boxes[i].x, in.boxes[i].x);
    EXPECT_DOUBLE_EQ(out.boxes[i].length, in.boxes[i].length);
    EXPECT_GE(out.boxes[i].score, 0.0f);
    EXPECT_LE(out.boxes[i].score, 1.0f);
  }
}

TEST(IntraRM, PermutingTheObjectsPermutesTheOutputs) {
  const IntraRM& m = trainedModule(4);
  std::mt19937 rng(21);
  const Detections in = test::randomFrame(rng, 40, 4).detections;
  const Detections out = m.refine(in);
  bool changed = false;
  for (std::size_t i = 0; i < in.size(); ++i) changed |= std::abs(out.boxes[i].x - in.boxes[i].x) > 1e-3;
  EXPECT_TRUE(changed) << "the module should move some boxes";
  std::vector<std::size_t> perm(in.size());
  std::iota(perm.begin(), perm.end(), 0);
  std::shuffle(perm.begin(), perm.end(), rng);
  Detections shuffled;
  shuffled.feature_dim = in.feature_dim;
  for (std::size_t k : perm) {
    shuffled.boxes.push_back(in.boxes[k]);
    shuffled.features.insert(shuffled.features.end(), in.feature(k), in.feature(k) + in.feature_dim);
  }
  const Detections out2 = m.refine(shuffled);
  ASSERT_EQ(out2.size(), in.size());
  for (std::size_t i = 0; i < perm.size(); ++i) expectBoxNear(out2.boxes[i], out.boxes[perm[i]]);
  EXPECT_EQ(out2.features, shuffled.features) << "features travel with their box";
}

TEST(IntraRM, NeighboursChangeTheResultOnlyWithEdges) {
  // The same object alone and with a close neighbour: with edges the refinement differs, without it must not.
  const IntraRM& m = trainedModule();
  std::mt19937 rng(4);
  Detections a = test::randomFrame(rng, 1).detections;
  a.boxes.resize(1);
  Detections b = a;
  Box n = a.boxes[0];
  n.x += 1.0;
  n.label = ObjectClass::Pedestrian;
  b.boxes.push_back(n);
  const double moved = std::abs(m.refine(a).boxes[0].x - m.refine(b).boxes[0].x) +
                       std::abs(m.refine(a).boxes[0].score - m.refine(b).boxes[0].score);
  EXPECT_GT(moved, 1e-6);
  Detections far = a;
  n.x += 10.0;  // beyond the 2 m radius: no influence
  far.boxes.push_back(n);
  expectBoxNear(m.refine(a).boxes[0], m.refine(far).boxes[0], 1e-5);
}

TEST(IntraRM, LoneObjectEmptyFrameAndAThousandObjects) {
  const IntraRM& m = trainedModule();
  const Detections empty;
  EXPECT_TRUE(m.refine(empty).empty());
  std::mt19937 rng(8);
  Detections one;
  one.boxes.push_back(test::randomObject(rng));
  const Detections r1 = m.refine(one);
  ASSERT_EQ(r1.size(), 1u);
  EXPECT_TRUE(std::isfinite(r1.boxes[0].x) && std::isfinite(r1.boxes[0].score));
  Detections many;
  for (int i = 0; i < 1000; ++i) many.boxes.push_back(test::randomObject(rng, 60));
  const Detections r = m.refine(many);
  ASSERT_EQ(r.size(), 1000u);
  for (const Box& b : r.boxes) {
    ASSERT_TRUE(std::isfinite(b.x) && std::isfinite(b.y) && std::isfinite(b.yaw) && std::isfinite(b.length));
    ASSERT_GE(b.score, 0.0f);
    ASSERT_LE(b.score, 1.0f);
  }
}

TEST(IntraRM, ModelTrainedWithFeaturesRefusesFeaturelessInput) {
  const IntraRM& m = trainedModule(4);
  std::mt19937 rng(2);
  Detections d = test::randomFrame(rng, 5).detections;  // feature_dim 0
  const std::string msg = ret3d::test::errorMessage<std::invalid_argument>([&] { m.refine(d); });
  EXPECT_NE(msg.find("trained with detector features (feature_dim 4)"), std::string::npos) << msg;
  Detections wrong = test::randomFrame(rng, 5, 3).detections;
  EXPECT_THROW(m.refine(wrong), std::invalid_argument);
  // A featureless model refines any detector's boxes, ignoring features they may carry.
  const Detections with = test::randomFrame(rng, 5, 3).detections;
  Detections without = with;
  without.feature_dim = 0;
  without.features.clear();
  const Detections r1 = trainedModule().refine(with), r2 = trainedModule().refine(without);
  for (std::size_t i = 0; i < with.size(); ++i) expectBoxNear(r1.boxes[i], r2.boxes[i], 1e-6);
  EXPECT_EQ(r1.feature_dim, 3u);
}

TEST(IntraRM, ScoreOnlyModelKeepsTheBoxGeometry) {
  // Two identical trainings (same seed and data), one with refine_boxes off: same scores, boxes untouched.
  auto train = [](bool refine_boxes) {
    IntraRMConfig c;
    c.model.hidden = 16;
    c.model.head_hidden = 16;
    c.model.refine_boxes = refine_boxes;
    c.train.lr = 1e-2;
    IntraRMLearner learner(c, 5);
    std::mt19937 rng(11);
    std::vector<IntraRMFrame> frames;
    for (int i = 0; i < 8; ++i) frames.push_back(test::randomFrame(rng, 12));
    learner.fitNormalisation(frames);
    std::vector<const IntraRMFrame*> batch;
    for (const auto& f : frames) batch.push_back(&f);
    for (int i = 0; i < 5; ++i) learner.step(batch);
    return learner.snapshot();
  };
  const IntraRM full = train(true), score_only = train(false);
  ret3d::test::TempDir tmp;
  score_only.save(tmp / "m.pt");
  IntraRMOptions o;
  o.model_path = tmp / "m.pt";
  const IntraRM loaded(o);
  EXPECT_FALSE(loaded.arch().refine_boxes);
  std::mt19937 rng(31);
  const Detections in = test::randomFrame(rng, 20).detections;
  const Detections a = full.refine(in), b = loaded.refine(in);
  bool moved = false;
  for (std::size_t i = 0; i < in.size(); ++i) {
    moved |= a.boxes[i].x != in.boxes[i].x;
    EXPECT_EQ(b.boxes[i].x, in.boxes[i].x);
    EXPECT_EQ(b.boxes[i].yaw, in.boxes[i].yaw);
    EXPECT_EQ(b.boxes[i].length, in.boxes[i].length);
    EXPECT_NEAR(b.boxes[i].score, a.boxes[i].score, 1e-6);
    EXPECT_NE(b.boxes[i].score, in.boxes[i].score);
  }
  EXPECT_TRUE(moved);
}

TEST(IntraRM, RejectsInconsistentInput) {
  Detections d;
  d.boxes.resize(2);
  d.feature_dim = 3;
  d.features.resize(5);
  EXPECT_THROW(trainedModule().refine(d), std::invalid_argument);
  Detections nan;
  nan.boxes.resize(1);
  nan.boxes[0].x = std::nan("");
  nan.boxes[0].length = nan.boxes[0].width = nan.boxes[0].height = 1;
  EXPECT_THROW(trainedModule().refine(nan), std::invalid_argument);
}

TEST(IntraRM, SaveThenLoadGivesIdenticalOutputs) {
  ret3d::test::TempDir tmp;
  const IntraRM& m = trainedModule(4);
  m.save(tmp / "m.pt");
  IntraRMOptions o;
  o.model_path = tmp / "m.pt";
  const IntraRM loaded(o);
  EXPECT_EQ(loaded.arch().feature_dim, 4u);
  EXPECT_EQ(loaded.arch().rounds, m.arch().rounds);
  EXPECT_EQ(loaded.arch().hidden, 16);
  std::mt19937 rng(9);
  const Detections in = test::randomFrame(rng, 30, 4).detections;
  const Detections a = m.refine(in), b = loaded.refine(in);
  for (std::size_t i = 0; i < in.size(); ++i) {
    EXPECT_EQ(a.boxes[i].x, b.boxes[i].x);
    EXPECT_EQ(a.boxes[i].yaw, b.boxes[i].yaw);
    EXPECT_EQ(a.boxes[i].score, b.boxes[i].score);
  }
  EXPECT_EQ(readIntraRMModelInfo(tmp / "m.pt").config.model.feature_dim, 4u);
}

std::string expectLoadError(const IntraRMOptions& o) {
  try {
    IntraRM m(o);
  } catch (const std::runtime_error& e) {
    return e.what();
  }
  ADD_FAILURE() << "loaded " << o.model_path;
  return "";
}

TEST(IntraRM, LoaderRefusesBadFilesAndMismatchesWithAMessage) {
  ret3d::test::TempDir tmp;
  trainedModule().save(tmp / "m.pt");
  IntraRMOptions o;
  o.model_path = tmp / "missing.pt";
  EXPECT_NE(expectLoadError(o).find("no such file"), std::string::npos);
  // Truncated: the first half of a valid file.
  {
    std::ifstream in(tmp / "m.pt", std::ios::binary);
    std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    std::ofstream out(tmp / "half.pt", std::ios::binary);
    out.write(bytes.data(), static_cast<std::streamsize>(bytes.size() / 2));
  }
  o.model_path = tmp / "half.pt";
  EXPECT_NE(expectLoadError(o).find("truncated or corrupt"), std::string::npos);
  {
    std::ofstream out(tmp / "text.pt");
    out << "not a model\n";
  }
  o.model_path = tmp / "text.pt";
  EXPECT_NE(expectLoadError(o).find("truncated or corrupt"), std::string::npos);
  o.model_path = tmp / "m.pt";
  o.radius = 4.0;
  EXPECT_NE(expectLoadError(o).find("radius"), std::string::npos);
  o.radius = -1;
  o.feature_dim = 64;
  EXPECT_NE(expectLoadError(o).find("features of length 0"), std::string::npos);
  o.feature_dim = -1;
  o.rounds = 6;
  EXPECT_NE(expectLoadError(o).find("4 rounds"), std::string::npos);
  o.rounds = 4;
  EXPECT_NO_THROW(IntraRM{o});
}

// Cost is reported, not asserted (the machine is shared): see `ret3d bench --stages intra` for the figures.
TEST(IntraRM, ReportsRefineTimeForFiftyAndThreeHundredObjects) {
  const IntraRM& m = trainedModule();
  std::mt19937 rng(13);
  for (int n : {50, 300}) {
    Detections d;
    for (int i = 0; i < n; ++i) d.boxes.push_back(test::randomObject(rng, 50));
    m.refine(d);
    const auto t0 = std::chrono::steady_clock::now();
    for (int k = 0; k < 20; ++k) m.refine(d);
    const double ms =
        std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count() / 20;
    RecordProperty("refine_ms_" + std::to_string(n), std::to_string(ms));
    std::cout << "IntraRM refine, " << n << " objects (hidden 16): " << ms << " ms\n";
  }
}

}  // namespace
}  // namespace relation
}  // namespace ret3d
