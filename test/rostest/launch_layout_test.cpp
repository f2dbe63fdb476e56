// rostest (test/rostest/launch_layout_test.test): launch/ret3d.launch loads the pipeline the stage table
// (include/ret3d/pipeline/stage_layout.h) describes, which ret3d_node, the nodelet bench and the offline pipeline read.
// The launch file is read by roslaunch's own XML loader (launch_nodes.py here, with the launch arguments given), for
// every combination of the stage switches (detector, intra, inter): the same nodelets in the same order with the same
// types, a switched-off stage bridged as the table says (not loaded, its reader remapped, or ~passthrough), and the
// `points` argument remapping the detector's input.
#include <gtest/gtest.h>

#include <array>
#include <cstdio>
#include <map>
#include <memory>
#include <sstream>
#include <string>
#include <vector>

#include "ret3d/pipeline/stage_layout.h"

namespace ret3d {
namespace {

// What the launch file starts, as launch_nodes.py prints it.
struct LaunchedNode {
  std::string name, type;
  std::map<std::string, std::string> remaps;
  std::string passthrough;  // "true" / "false"; empty when the launch file sets none
};

std::vector<LaunchedNode> readLaunch(const std::string& args) {
  const std::string command = std::string("/usr/bin/python3 ") + RET3D_SOURCE_DIR + "/test/rostest/launch_nodes.py " +
                              RET3D_SOURCE_DIR + "/launch/ret3d.launch " + args + " 2>&1";
  std::unique_ptr<FILE, int (*)(FILE*)> pipe(popen(command.c_str(), "r"), pclose);
  if (!pipe) throw std::runtime_error("cannot run " + command);
  std::string text;
  std::array<char, 4096> buffer{};
  while (fgets(buffer.data(), buffer.size(), pipe.get())) text += buffer.data();
  std::vector<LaunchedNode> nodes;
  std::istringstream lines(text);
  for (std::string line; std::getline(lines, line);) {
    std::istringstream in(line);
    std::string kind, name, a, b;
    in >> kind >> name >> a >> b;
    if (kind == "node") nodes.push_back({name, a, {}, ""});
    else if ((kind == "remap" || kind == "param") && !nodes.empty() && nodes.back().name == name)
      (kind == "remap" ? nodes.back().remaps[a] : nodes.back().passthrough) = b;
    else throw std::runtime_error(command + ": unexpected output:\n" + text);
  }
  return nodes;
}

TEST(LaunchLayout, EverySwitchCombinationMatchesTheStageTable) {
  std::vector<std::string> switches;
  for (const pipeline::StageLayout& s : pipeline::pipelineLayout())
    if (!s.switch_arg.empty()) switches.push_back(s.switch_arg);
  ASSERT_EQ(switches.size(), 3u) << "detector, intra, inter";
  for (unsigned mask = 0; mask < (1u << switches.size()); ++mask) {
    std::map<std::string, bool> on;
    std::string args = "points:=/velodyne_points";
    for (std::size_t i = 0; i < switches.size(); ++i) {
      on[switches[i]] = !(mask & (1u << i));
      args += " " + switches[i] + ":=" + (on[switches[i]] ? "true" : "false");
    }
    SCOPED_TRACE(args);
    const std::vector<LaunchedNode> launched = readLaunch(args);
    const std::vector<pipeline::NodeletLoad> expected = pipeline::nodeletsToLoad(on);
    ASSERT_EQ(launched.size(), expected.size());
    for (std::size_t k = 0; k < expected.size(); ++k) {
      const pipeline::StageLayout& stage = *expected[k].stage;
      SCOPED_TRACE(stage.node + " (" + pipeline::whenOffName(stage.off) + " when off)");
      EXPECT_EQ(launched[k].name, stage.node);
      EXPECT_EQ(launched[k].type, stage.nodelet);
      std::map<std::string, std::string> remaps = expected[k].remaps;
      if (stage.input == "points") remaps["points"] = "/velodyne_points";  // the launch argument `points`
      EXPECT_EQ(launched[k].remaps, remaps);
      // A stage that runs as a passthrough when off gets ~passthrough either way; no other stage has one.
      const bool has_passthrough = stage.off == pipeline::WhenOff::Passthrough;
      EXPECT_EQ(launched[k].passthrough, has_passthrough ? (expected[k].passthrough ? "true" : "false") : "");
    }
  }
}

TEST(LaunchLayout, ASwitchedOffStageIsBridgedOnTheTopicsOfTheTable) {
  // intra:=false: the tracker reads what IntraRM would have read; inter:=false: InterRM still publishes `objects`.
  const std::vector<LaunchedNode> launched = readLaunch("intra:=false inter:=false");
  std::map<std::string, LaunchedNode> by_name;
  for (const LaunchedNode& n : launched) by_name[n.name] = n;
  EXPECT_EQ(by_name.count("ret3d_intra"), 0u);
  ASSERT_EQ(by_name.count("ret3d_tracker"), 1u);
  EXPECT_EQ(by_name["ret3d_tracker"].remaps, (std::map<std::string, std::string>{{"detections_intra", "detections"}}));
  EXPECT_EQ(by_name["ret3d_inter"].passthrough, "true");
}

}  // namespace
}  // namespace ret3d
