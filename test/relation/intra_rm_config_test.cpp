#include "ret3d/relation/intra_rm_config.h"

#include <gtest/gtest.h>

namespace ret3d {
namespace relation {
namespace {

TEST(IntraRMConfig, ParsesRoundTripsAndRejectsTypos) {
  const IntraRMConfig c = parseIntraRMConfig(
      "model: {radius: 4.0, rounds: 6, use_edges: false}\n"
      "train: {epochs: 3, cls_pos_iou: {Car: 0.6}}\n");
  EXPECT_DOUBLE_EQ(c.model.radius, 4.0);
  EXPECT_EQ(c.model.rounds, 6);
  EXPECT_FALSE(c.model.use_edges);
  EXPECT_EQ(c.train.epochs, 3);
  EXPECT_DOUBLE_EQ(c.train.cls_pos_iou[0], 0.6);
  EXPECT_DOUBLE_EQ(c.train.cls_pos_iou[1], 0.5);
  EXPECT_DOUBLE_EQ(c.train.lr, 3e-4);
  const IntraRMConfig back = parseIntraRMConfig(toYaml(c));
  EXPECT_EQ(toYaml(back), toYaml(c));
  try {
    parseIntraRMConfig("model: {radious: 2}\n", "x.yaml");
    FAIL();
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("x.yaml: key 'model.radious': unknown key"), std::string::npos) << e.what();
  }
  EXPECT_THROW(parseIntraRMConfig("model: {rounds: 0}\n"), std::invalid_argument);
  EXPECT_THROW(parseIntraRMConfig("model: {rounds: two}\n"), std::invalid_argument);
  EXPECT_THROW(parseIntraRMConfig("train: {cls_pos_iou: {Truck: 0.5}}\n"), std::invalid_argument);
}

TEST(IntraRMConfig, ShippedConfigsLoad) {
  for (const char* name : {"intra_rm.yaml", "intra_no_edge.yaml", "intra_r1.yaml", "intra_r4.yaml", "intra_m1.yaml",
                           "intra_m2.yaml", "intra_m6.yaml"}) {
    EXPECT_NO_THROW(loadIntraRMConfig(std::string(RET3D_SOURCE_DIR) + "/config/relation/" + name)) << name;
  }
  const IntraRMConfig def = loadIntraRMConfig(std::string(RET3D_SOURCE_DIR) + "/config/relation/intra_rm.yaml");
  EXPECT_DOUBLE_EQ(def.model.radius, 2.0);
  EXPECT_EQ(def.model.rounds, 4);
  EXPECT_EQ(def.train.frames_per_batch, 16);
  EXPECT_DOUBLE_EQ(def.train.loc_weight, 2.0);
  EXPECT_DOUBLE_EQ(def.train.dir_weight, 0.2);
}

}  // namespace
}  // namespace relation
}  // namespace ret3d
