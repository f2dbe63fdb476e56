// The pipeline's layout, written once: its stages in order, each with its nodelet (node name and plugin type), the
// topics it reads and writes (relative names, as launch/ret3d.launch uses them), the `ret3d detect --stages` name of
// the offline stage it runs, the launch argument that switches it off and what happens then. Read by the all-in-one
// node (src/ros/ret3d_node.cpp), the nodelet bench (src/tools), the offline pipeline (parseStages) and a rostest that
// checks launch/ret3d.launch against it (test/rostest/launch_layout_test). No ROS here: plain names only.
#pragma once

#include <map>
#include <string>
#include <vector>

namespace ret3d {
namespace pipeline {

// What a stage switched off (its launch argument false) becomes.
enum class WhenOff {
  AlwaysOn,     // no switch: always loaded
  LeftToOthers, // not loaded; its output topic is left to another producer (detector:=false)
  Bridged,      // not loaded; the stage reading its output reads its input instead (intra:=false: a remap)
  Passthrough,  // loaded with ~passthrough true: no model, its input forwarded as its output (inter:=false; the
                // message types differ, so a remap cannot bridge it)
};

struct StageLayout {
  std::string node;     // node name (the section of config/ret3d.yaml): "ret3d_detector"
  std::string nodelet;  // plugin type: "ret3d/DetectorNodelet"
  std::string offline;  // `ret3d detect --stages` name ("base"); empty: no offline stage (the markers)
  std::string input, output;  // relative topic names
  std::string switch_arg;     // the launch argument / ret3d_node's private bool switching it; empty when AlwaysOn
  WhenOff off = WhenOff::AlwaysOn;
};

// The stages in pipeline order: detector, IntraRM, tracker, InterRM, markers.
const std::vector<StageLayout>& pipelineLayout();

// The offline stage names in order: base, intra, track, inter.
std::vector<std::string> offlineStageNames();

// One nodelet to load: its stage, the topic remaps it gets (relative from -> relative to) and whether it runs as a
// passthrough (~passthrough true).
struct NodeletLoad {
  const StageLayout* stage = nullptr;
  std::map<std::string, std::string> remaps;
  bool passthrough = false;
  // The topic it reads after the remaps.
  std::string input() const;
};

// The nodelets launch/ret3d.launch loads for the switches given (launch argument -> value; a switch not given is
// on), in pipeline order. Throws std::invalid_argument naming an unknown switch.
std::vector<NodeletLoad> nodeletsToLoad(const std::map<std::string, bool>& switches);

// The name of a WhenOff value, for messages and tests ("bridged").
std::string whenOffName(WhenOff off);

}  // namespace pipeline
}  // namespace ret3d
