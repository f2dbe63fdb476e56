// `rosrun ret3d ret3d_node`: the whole pipeline in one process, for a quick start without a launch file. The same
// nodelets as launch/ret3d.launch (same names, so the same parameters apply: config/ret3d.yaml loaded by rosparam, or
// the built-in defaults, which are that file's values), loaded in-process by a nodelet::Loader.
// Private parameters: ~detector, ~intra, ~inter (bool, default true: a stage off is bridged as in the launch file;
// both follow the one stage table, include/ret3d/pipeline/stage_layout.h). Command-line remappings (e.g.
// points:=/velodyne_points) apply to every stage.
#include <nodelet/loader.h>
#include <ros/ros.h>

#include <cstdlib>
#include <map>
#include <string>
#include <vector>

#include "ret3d/pipeline/stage_layout.h"

using namespace ret3d;

int main(int argc, char** argv) {
  // Before the nodelets' library (and with it libtorch's OpenMP runtime) is loaded, which reads it once: waiting
  // OpenMP threads sleep instead of spinning, or any other busy process on the cores slows the detector's network
  // some 25 times (launch/ret3d.launch sets the same for its manager). A value the user set is kept.
  setenv("OMP_WAIT_POLICY", "PASSIVE", /*overwrite=*/0);
  ros::init(argc, argv, "ret3d");
  ros::NodeHandle private_nh("~");
  // The stages and how one switched off is bridged: the one table launch/ret3d.launch is checked against.
  std::map<std::string, bool> switches;
  for (const pipeline::StageLayout& s : pipeline::pipelineLayout())
    if (!s.switch_arg.empty()) private_nh.param(s.switch_arg, switches[s.switch_arg], true);

  nodelet::Loader loader(private_nh);
  const ros::M_string remappings = ros::names::getRemappings();
  const std::vector<std::string> no_argv;
  const std::string ns = ros::this_node::getNamespace() == "/" ? "/" : ros::this_node::getNamespace() + "/";
  for (const pipeline::NodeletLoad& n : pipeline::nodeletsToLoad(switches)) {
    if (n.passthrough) ros::param::set(ns + n.stage->node + "/passthrough", true);
    ros::M_string remap = remappings;
    // A bridge follows the user's remapping of the topic it leads to.
    for (const auto& [from, to] : n.remaps) {
      const std::string target = ros::names::resolve(to);
      remap[ros::names::resolve(from)] = remap.count(target) ? remap.at(target) : target;
    }
    if (!loader.load(ns + n.stage->node, n.stage->nodelet, remap, no_argv)) {
      ROS_FATAL("ret3d_node: %s (%s) did not start; see the message above", n.stage->node.c_str(),
                n.stage->nodelet.c_str());
      return 1;
    }
  }
  const bool detector = switches.at("detector"), intra = switches.at("intra"), inter = switches.at("inter");
  ROS_INFO("ret3d_node: pipeline running (detector %s, IntraRM %s, InterRM %s)", detector ? "on" : "off",
           intra ? "on" : "off", inter ? "on" : "refining off (pass-through)");
  ros::spin();
  return 0;
}
