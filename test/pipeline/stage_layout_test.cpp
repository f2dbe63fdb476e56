// The pipeline's one stage table: a chain from `points` to `objects`, each stage switched off as documented, and the
// offline stage names (and their order) that `ret3d detect --stages` accepts.
#include "ret3d/pipeline/stage_layout.h"

#include <set>
#include <stdexcept>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "ret3d/pipeline/offline_pipeline.h"
#include "support/error_message.h"

namespace ret3d {
namespace pipeline {
namespace {

// Every loaded stage reads `points` (the sensor), what another producer publishes (`detections` with the detector
// off) or an output of a stage loaded before it.
void expectConnected(const std::vector<NodeletLoad>& loads, const std::string& external) {
  std::set<std::string> published = {"points", external};
  for (const NodeletLoad& n : loads) {
    EXPECT_TRUE(published.count(n.input())) << n.stage->node << " reads " << n.input() << ", which nobody publishes";
    published.insert(n.stage->output);
  }
}

TEST(StageLayout, AllOnIsOneChainFromPointsToObjects) {
  const std::vector<NodeletLoad> loads = nodeletsToLoad({});
  ASSERT_EQ(loads.size(), pipelineLayout().size());
  for (const NodeletLoad& n : loads) {
    EXPECT_TRUE(n.remaps.empty()) << n.stage->node;
    EXPECT_FALSE(n.passthrough) << n.stage->node;
  }
  EXPECT_EQ(loads.front().input(), "points");
  expectConnected(loads, "");
  EXPECT_EQ(loads[3].stage->output, "objects");
}

TEST(StageLayout, EachSwitchedOffStageIsBridgedAsDocumented) {
  for (const bool detector : {true, false})
    for (const bool intra : {true, false})
      for (const bool inter : {true, false}) {
        SCOPED_TRACE(std::to_string(detector) + std::to_string(intra) + std::to_string(inter));
        const auto loads = nodeletsToLoad({{"detector", detector}, {"intra", intra}, {"inter", inter}});
        std::set<std::string> nodes;
        for (const NodeletLoad& n : loads) nodes.insert(n.stage->node);
        EXPECT_EQ(nodes.count("ret3d_detector"), detector ? 1u : 0u);
        EXPECT_EQ(nodes.count("ret3d_intra"), intra ? 1u : 0u);
        EXPECT_EQ(nodes.count("ret3d_inter"), 1u);  // a passthrough when off: `objects` still comes out
        EXPECT_EQ(nodes.count("ret3d_tracker") + nodes.count("ret3d_markers"), 2u);
        expectConnected(loads, detector ? "" : "detections");
        for (const NodeletLoad& n : loads) {
          EXPECT_EQ(n.passthrough, n.stage->node == "ret3d_inter" && !inter);
          if (n.stage->node == "ret3d_tracker") {
            EXPECT_EQ(n.input(), intra ? "detections_intra" : "detections");
          }
        }
      }
}

TEST(StageLayout, AnUnknownSwitchIsRefusedByName) {
  EXPECT_THROW(nodeletsToLoad({{"tracker", false}}), std::invalid_argument);
  const std::string message = test::errorMessage<std::invalid_argument>([] { nodeletsToLoad({{"tracker", false}}); });
  EXPECT_NE(message.find("'tracker'"), std::string::npos) << message;
}

TEST(StageLayout, OfflineStagesFollowTheTable) {
  EXPECT_EQ(offlineStageNames(), (std::vector<std::string>{"base", "intra", "track", "inter"}));
  EXPECT_EQ(parseStages("base,intra,track"), (std::vector<std::string>{"base", "intra", "track"}));
  EXPECT_NE(test::errorMessage([] { parseStages("intra,base"); }).find("the order is base, intra, track, inter"),
            std::string::npos);
  EXPECT_NE(test::errorMessage([] { parseStages("markers"); }).find("known: base, intra, track, inter, none"),
            std::string::npos);
}

}  // namespace
}  // namespace pipeline
}  // namespace ret3d
