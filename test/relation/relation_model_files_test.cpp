// The model files and learner checkpoints IntraRM and InterRM share (src/relation/model_archive.*,
// learner_checkpoint.h): the repository's model files, written before that code was shared, still load, and what a
// module saves of them loads back to the same outputs and metadata; an InterRM learner resumes from its checkpoint as
// IntraRM's does.
#include <random>
#include <utility>
#include <vector>

#include <fstream>

#include <gtest/gtest.h>

#include "ret3d/relation/inter_rm.h"
#include "ret3d/relation/inter_rm_learner.h"
#include "ret3d/relation/intra_rm.h"
#include "support/inter_rm_scenes.h"
#include "support/intra_rm_scenes.h"
#include "support/test_util.h"

namespace ret3d {
namespace relation {
namespace {

const std::string kModels = std::string(RET3D_SOURCE_DIR) + "/models/";

bool identical(const Box& a, const Box& b) {
  return a.x == b.x && a.y == b.y && a.z == b.z && a.length == b.length && a.width == b.width &&
         a.height == b.height && a.yaw == b.yaw && a.score == b.score && a.label == b.label;
}

// The module in the repository's file `model`, and the one it saves loaded back, which has the same metadata.
template <class Module, class Options>
std::pair<Module, Module> loadAndSaveBack(const std::string& model, const ret3d::test::TempDir& tmp) {
  Options o;
  o.model_path = kModels + model;
  Module m(o);
  m.save(tmp / "m.pt");
  o.model_path = tmp / "m.pt";
  Module back(o);
  EXPECT_EQ(toYaml(back.info().config), toYaml(m.info().config));
  EXPECT_EQ(back.info().trained_on, m.info().trained_on);
  EXPECT_EQ(back.info().format_version, m.info().format_version);
  return {std::move(m), std::move(back)};
}

TEST(RelationModelFiles, RepositoryIntraRMFilesLoadAndSaveBackUnchanged) {
  for (const std::string model : {"lwd3d/intra_rm.pt", "kitti_pointrcnn/intra_rm.pt"}) {
    SCOPED_TRACE(model);
    ret3d::test::TempDir tmp;
    const auto [m, back] = loadAndSaveBack<IntraRM, IntraRMOptions>(model, tmp);
    std::mt19937 rng(4);
    const Detections in = test::randomFrame(rng, 40, m.arch().feature_dim).detections;
    const Detections a = m.refine(in), b = back.refine(in);
    ASSERT_EQ(a.size(), in.size());
    for (std::size_t i = 0; i < in.size(); ++i) EXPECT_TRUE(identical(a.boxes[i], b.boxes[i])) << i;
  }
}

TEST(RelationModelFiles, RepositoryInterRMFilesLoadAndSaveBackUnchanged) {
  std::vector<InterRMSequence> sequences;
  for (const InterRMSample& s : ret3d::test::makeInterSamples(20, 6)) sequences.push_back(s.sequence);
  for (const std::string model : {"lwd3d/inter_rm.pt", "kitti_pointrcnn/inter_rm.pt"}) {
    SCOPED_TRACE(model);
    ret3d::test::TempDir tmp;
    const auto [m, back] = loadAndSaveBack<InterRM, InterRMOptions>(model, tmp);
    const std::vector<Box> a = m.refine(sequences), b = back.refine(sequences);
    ASSERT_EQ(a.size(), sequences.size());
    std::size_t moved = 0;
    for (std::size_t i = 0; i < a.size(); ++i) {
      EXPECT_TRUE(identical(a[i], b[i])) << i;
      moved += !identical(a[i], sequences[i].boxes[0]);
    }
    // The PointRCNN file is the identity module (its model card: no epoch beat the input boxes); the other moves them.
    if (model == "lwd3d/inter_rm.pt") EXPECT_GT(moved, 0u);
  }
}

TEST(RelationModelFiles, InterRMCheckpointResumesTheSameState) {
  ret3d::test::TempDir tmp;
  InterRMConfig c;
  c.model.c_enc = 32;
  c.model.heads = 4;
  const auto samples = ret3d::test::makeInterSamples(64, 3);
  std::vector<const InterRMSample*> batch;
  for (const auto& s : samples) batch.push_back(&s);
  InterRMLearner a(c, 3);
  a.setTrainedOn("test run");
  a.fitNormalisation(samples);
  a.step(batch);
  a.saveCheckpoint(tmp.path(), 1, 0.25);
  InterRMLearner b(c, 99);
  int epoch = 0;
  double best = 0;
  ASSERT_TRUE(b.loadCheckpoint(tmp.path(), &epoch, &best));
  EXPECT_EQ(epoch, 1);
  EXPECT_DOUBLE_EQ(best, 0.25);
  EXPECT_EQ(b.model().info().trained_on, "test run");
  EXPECT_DOUBLE_EQ(a.evaluate(samples).total, b.evaluate(samples).total);
  // The next steps (optimiser moments and augmentation draws restored) agree too.
  a.step(batch);
  b.step(batch);
  EXPECT_NEAR(a.evaluate(samples).total, b.evaluate(samples).total, 1e-6);
  InterRMConfig other = c;
  other.model.c_enc = 64;
  InterRMLearner d(other, 3);
  try {
    d.loadCheckpoint(tmp.path(), &epoch, &best);
    ADD_FAILURE() << "a checkpoint of another network was loaded";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("InterRM checkpoint " + tmp.path()), std::string::npos) << e.what();
  }
  // A damaged state file is refused naming the file and the key.
  for (const std::string& state : {"epoch: 1\nbest_val: 0.25\n", "epoch: one\nbest_val: 0.25\nrng: '1'\n",
                                   "epoch: 1\nbest_val: 0.25\nrng: x\n", "[1, 2"}) {
    std::ofstream(tmp / "state.yaml") << state;
    InterRMLearner e(c, 3);
    try {
      e.loadCheckpoint(tmp.path(), &epoch, &best);
      ADD_FAILURE() << "loaded a state file holding: " << state;
    } catch (const std::runtime_error& err) {
      EXPECT_NE(std::string(err.what()).find(tmp / "state.yaml"), std::string::npos) << err.what();
    }
  }
}

}  // namespace
}  // namespace relation
}  // namespace ret3d
