// InterRM (Ret3D §3.3): padding, one-entry histories, permutation, model files, and that training learns.
#include "ret3d/relation/inter_rm.h"

#include <chrono>
#include <cmath>
#include <fstream>
#include <iostream>

#include <gtest/gtest.h>

#include "ret3d/relation/inter_rm_learner.h"
#include "ret3d/relation/intra_rm.h"  // setTorchThreads
#include "support/inter_rm_scenes.h"
#include "support/test_util.h"

namespace ret3d {
namespace relation {
namespace {

InterRMConfig smallConfig(InterPositionalEncoding pe = InterPositionalEncoding::Implicit) {
  InterRMConfig c;
  c.model.c_enc = 32;
  c.model.heads = 4;
  c.model.positional_encoding = pe;
  c.train.sequences_per_batch = 32;
  return c;
}

// A module with non-zero weights everywhere (an untrained one is the identity, which would make the checks vacuous).
InterRM trainedModule(InterPositionalEncoding pe, int steps = 30) {
  InterRMLearner learner(smallConfig(pe), 3);
  const auto train = test::makeInterSamples(512, 11);
  learner.fitNormalisation(train);
  for (int s = 0; s < steps; ++s) {
    std::vector<const InterRMSample*> batch;
    for (int k = 0; k < 32; ++k) batch.push_back(&train[static_cast<std::size_t>((s * 32 + k) % 512)]);
    learner.step(batch);
  }
  test::TempDir dir;
  learner.model().save(dir / "m.pt");
  InterRMOptions o;
  o.model_path = dir / "m.pt";
  return InterRM(o);
}

double boxDiff(const Box& a, const Box& b) {
  return std::max({std::abs(a.x - b.x), std::abs(a.y - b.y), std::abs(a.z - b.z), std::abs(a.length - b.length),
                   std::abs(a.width - b.width), std::abs(a.height - b.height), std::abs(wrapAngle(a.yaw - b.yaw))});
}

class InterRMPe : public ::testing::TestWithParam<InterPositionalEncoding> {};

TEST_P(InterRMPe, PaddingNeverChangesTheRealEntriesOutput) {
  const InterRM m = trainedModule(GetParam());
  std::mt19937_64 rng(5);
  const InterRMSequence shortest = test::makeInterSample(rng, 3).sequence;
  const auto alone = m.refine({shortest});
  ASSERT_EQ(alone.size(), 1u);
  // The refinement is not the identity (otherwise this test would prove nothing).
  EXPECT_GT(boxDiff(alone[0], shortest.boxes[0]), 1e-4);
  const auto batched =
      m.refine({test::makeInterSample(rng, 25).sequence, shortest, test::makeInterSample(rng, 12).sequence});
  ASSERT_EQ(batched.size(), 3u);
  EXPECT_LT(boxDiff(alone[0], batched[1]), 1e-5) << positionalEncodingName(GetParam());
}

INSTANTIATE_TEST_SUITE_P(AllEncodings, InterRMPe,
                         ::testing::Values(InterPositionalEncoding::Implicit, InterPositionalEncoding::Temporal,
                                           InterPositionalEncoding::Spatial));

TEST(InterRM, OneEntryHistoryWorks) {
  const InterRM m = trainedModule(InterPositionalEncoding::Implicit);
  InterRMSequence s;
  Box b;
  b.x = 12, b.y = -3, b.z = -0.7, b.length = 4, b.width = 1.7, b.height = 1.5, b.yaw = 0.4;
  b.label = ObjectClass::Car, b.score = 0.9f, b.track_id = 42, b.vx = 1, b.vy = 2;
  s.boxes = {b};
  s.dt = {0.0};
  const auto out = m.refine({s});
  ASSERT_EQ(out.size(), 1u);
  const Box& r = out[0];
  for (double v : {r.x, r.y, r.z, r.length, r.width, r.height, r.yaw}) EXPECT_TRUE(std::isfinite(v));
  // A refinement, not a different object: within a metre, and the identity fields kept.
  EXPECT_LT(std::hypot(r.x - b.x, r.y - b.y), 1.0);
  EXPECT_EQ(r.track_id, 42u);
  EXPECT_EQ(r.label, ObjectClass::Car);
  EXPECT_FLOAT_EQ(r.score, 0.9f);
  EXPECT_DOUBLE_EQ(r.vx, 1.0);
}

TEST(InterRM, PermutingTracksPermutesOutputs) {
  const InterRM m = trainedModule(InterPositionalEncoding::Implicit);
  const auto samples = test::makeInterSamples(6, 21);
  std::vector<InterRMSequence> seqs, perm;
  const std::vector<std::size_t> order{3, 0, 5, 1, 4, 2};
  for (const auto& s : samples) seqs.push_back(s.sequence);
  for (std::size_t i : order) perm.push_back(seqs[i]);
  const auto a = m.refine(seqs), b = m.refine(perm);
  ASSERT_EQ(a.size(), 6u);
  for (std::size_t k = 0; k < order.size(); ++k) EXPECT_LT(boxDiff(b[k], a[order[k]]), 1e-5) << k;
}

TEST(InterRM, UntrainedModuleIsTheIdentity) {
  InterRMArch arch;
  const InterRM m(arch, 4);
  const auto samples = test::makeInterSamples(3, 8);
  std::vector<InterRMSequence> seqs;
  for (const auto& s : samples) seqs.push_back(s.sequence);
  const auto out = m.refine(seqs);
  for (std::size_t i = 0; i < seqs.size(); ++i) EXPECT_LT(boxDiff(out[i], seqs[i].boxes[0]), 1e-9);
}

TEST(InterRM, LongSequencesKeepTheNewestMaxHistoryEntries) {
  const InterRM m = trainedModule(InterPositionalEncoding::Implicit);
  std::mt19937_64 rng(9);
  InterRMSequence longer = test::makeInterSample(rng, 60).sequence;
  InterRMSequence cut = longer;
  cut.boxes.resize(30);
  cut.dt.resize(30);
  EXPECT_LT(boxDiff(m.refine({longer})[0], m.refine({cut})[0]), 1e-6);
}

TEST(InterRM, SaveLoadGivesIdenticalOutputs) {
  const InterRM m = trainedModule(InterPositionalEncoding::Temporal, 10);
  test::TempDir dir;
  m.save(dir / "inter.pt");
  InterRMOptions o;
  o.model_path = dir / "inter.pt";
  const InterRM loaded(o);
  EXPECT_EQ(loaded.arch().c_enc, 32);
  EXPECT_EQ(loaded.arch().positional_encoding, InterPositionalEncoding::Temporal);
  const auto samples = test::makeInterSamples(5, 33);
  std::vector<InterRMSequence> seqs;
  for (const auto& s : samples) seqs.push_back(s.sequence);
  const auto a = m.refine(seqs), b = loaded.refine(seqs);
  for (std::size_t i = 0; i < a.size(); ++i) EXPECT_EQ(boxDiff(a[i], b[i]), 0.0) << i;
}

std::string errorOf(const InterRMOptions& o) {
  try {
    InterRM m(o);
  } catch (const std::runtime_error& e) {
    return e.what();
  }
  return "";
}

TEST(InterRM, LoaderRefusesMismatchTruncationAndOtherFiles) {
  const InterRM m = trainedModule(InterPositionalEncoding::Implicit, 1);
  test::TempDir dir;
  m.save(dir / "inter.pt");
  InterRMOptions o;
  o.model_path = dir / "inter.pt";
  o.c_enc = 256;
  EXPECT_NE(errorOf(o).find("C_enc 32"), std::string::npos) << errorOf(o);
  o.c_enc = -1;
  o.positional_encoding = "spatial";
  EXPECT_NE(errorOf(o).find("implicit positional encoding"), std::string::npos) << errorOf(o);
  o.positional_encoding.clear();
  EXPECT_EQ(errorOf(o), "");

  // Truncated: half the bytes.
  std::ifstream in(dir / "inter.pt", std::ios::binary);
  const std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  std::ofstream(dir / "half.pt", std::ios::binary) << bytes.substr(0, bytes.size() / 2);
  o.model_path = dir / "half.pt";
  EXPECT_NE(errorOf(o).find("truncated or corrupt"), std::string::npos) << errorOf(o);
  o.model_path = dir / "missing.pt";
  EXPECT_NE(errorOf(o).find("no such file"), std::string::npos) << errorOf(o);
  std::ofstream(dir / "text.pt") << "not a model\n";
  o.model_path = dir / "text.pt";
  EXPECT_NE(errorOf(o).find("InterRM model"), std::string::npos) << errorOf(o);
}

TEST(InterRM, BadSequencesAreRefusedWithAMessage) {
  const InterRM m(InterRMArch{}, 1);
  InterRMSequence empty;
  EXPECT_THROW(m.refine({empty}), std::invalid_argument);
  std::mt19937_64 rng(1);
  InterRMSequence s = test::makeInterSample(rng, 4).sequence;
  s.dt.pop_back();
  EXPECT_THROW(m.refine({s}), std::invalid_argument);
  s = test::makeInterSample(rng, 4).sequence;
  s.boxes[2].x = std::nan("");
  EXPECT_THROW(m.refine({s}), std::invalid_argument);
  EXPECT_TRUE(m.refine({}).empty());
}

TEST(InterRMLearner, ATinyTrainingRunLowersTheHeldOutLoss) {
  InterRMConfig c = smallConfig();
  c.train.lr = 1e-3;
  InterRMLearner learner(c, 2);
  const auto train = test::makeInterSamples(1024, 1), val = test::makeInterSamples(256, 2);
  learner.fitNormalisation(train);
  const double before = learner.evaluate(val).total;
  for (int epoch = 0; epoch < 4; ++epoch) {
    for (std::size_t b = 0; b + 32 <= train.size(); b += 32) {
      std::vector<const InterRMSample*> batch;
      for (std::size_t k = b; k < b + 32; ++k) batch.push_back(&train[k]);
      learner.step(batch);
    }
  }
  const double after = learner.evaluate(val).total;
  std::cout << "held-out smooth-L1: " << before << " (input boxes) -> " << after << " (after 128 steps)\n";
  // The history of a constant-velocity object averages its detection noise: a clear gain, not a rounding one.
  EXPECT_LT(after, 0.8 * before);
}

TEST(InterRMLearner, ResidualsInvertTheRefinement) {
  Box c;
  c.x = 3, c.y = 4, c.z = -1, c.length = 4, c.width = 2, c.height = 1.5, c.yaw = 2.5;
  Box t = c;
  t.x += 0.3, t.y -= 0.2, t.length = 4.4, t.yaw = wrapAngle(c.yaw + 0.1 + M_PI);  // flipped heading: mod pi
  const auto r = interResiduals(c, t);
  EXPECT_NEAR(std::hypot(r[0], r[1]), std::hypot(0.3, 0.2), 1e-6);
  EXPECT_NEAR(r[3], std::log(1.1), 1e-6);
  EXPECT_NEAR(r[6], 0.1, 1e-6);
}

TEST(InterRMConfig, DefaultFileMatchesBuiltInAndTyposFail) {
  const InterRMConfig file = loadInterRMConfig(std::string(RET3D_SOURCE_DIR) + "/config/relation/inter_rm.yaml");
  EXPECT_EQ(toYaml(file), toYaml(InterRMConfig{}));
  EXPECT_EQ(file.model.c_enc, 256);
  EXPECT_EQ(file.model.heads, 16);
  EXPECT_EQ(file.train.sequences_per_batch, 64);
  EXPECT_DOUBLE_EQ(file.train.lr, 3e-4);
  for (const char* v : {"temporal", "spatial"}) {
    const InterRMConfig pe =
        loadInterRMConfig(std::string(RET3D_SOURCE_DIR) + "/config/relation/inter_pe_" + v + ".yaml");
    EXPECT_STREQ(positionalEncodingName(pe.model.positional_encoding), v);
  }
  EXPECT_THROW(parseInterRMConfig("model:\n  c_ecn: 64\n"), std::invalid_argument);
  EXPECT_THROW(parseInterRMConfig("model:\n  heads: 7\n"), std::invalid_argument);
  EXPECT_THROW(parseInterRMConfig("model:\n  positional_encoding: learned\n"), std::invalid_argument);
  EXPECT_EQ(parseInterRMConfig(toYaml(parseInterRMConfig("model:\n  c_enc: 64\n"))).model.c_enc, 64);
}

// Cost of the default module (C_enc 256, 16 heads) for 50 tracks with 30 entries each, on 2 threads: reported, not
// asserted (timing depends on the machine's load).
TEST(InterRM, ReportsTheCostOf50Tracks) {
  InterRMArch arch;
  const InterRM m(arch, 1);
  std::vector<InterRMSequence> seqs;
  std::mt19937_64 rng(3);
  for (int i = 0; i < 50; ++i) seqs.push_back(test::makeInterSample(rng, 30).sequence);
  for (int threads : {1, 2}) {
    setTorchThreads(threads);
    m.refine(seqs);  // warm-up
    const int reps = 20;
    double best = 1e9;
    for (int r = 0; r < reps; ++r) {
      const auto t0 = std::chrono::steady_clock::now();
      m.refine(seqs);
      best = std::min(best, 1000 * std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count());
    }
    std::cout << "InterRM (C_enc 256, 16 heads), 50 tracks x 30 entries, " << threads << " thread(s): best of " << reps
              << " " << best << " ms\n";
  }
  setTorchThreads(2);
}

}  // namespace
}  // namespace relation
}  // namespace ret3d
