// `rosrun ret3d ret3d_node`: the whole pipeline in one process, for a quick start without a launch file. The same
// nodelets as launch/ret3d.launch (same names, so the same parameters apply: config/ret3d.yaml loaded by rosparam, or
// the built-in defaults, which are that file's values), loaded in-process by a nodelet::Loader.
// Private parameters: ~detector, ~intra, ~inter (bool, default true: a relation stage off is bridged as in the launch
// file). Command-line remappings (e.g. points:=/velodyne_points) apply to every stage.
#include <nodelet/loader.h>
#include <ros/ros.h>

#include <cstdlib>
#include <map>
#include <string>
#include <vector>

int main(int argc, char** argv) {
  // Before the nodelets' library (and with it libtorch's OpenMP runtime) is loaded, which reads it once: waiting
  // OpenMP threads sleep instead of spinning, or any other busy process on the cores slows the detector's network
  // some 25 times (launch/ret3d.launch sets the same for its manager). A value the user set is kept.
  setenv("OMP_WAIT_POLICY", "PASSIVE", /*overwrite=*/0);
  ros::init(argc, argv, "ret3d");
  ros::NodeHandle private_nh("~");
  bool detector = true, intra = true, inter = true;
  private_nh.param("detector", detector, true);
  private_nh.param("intra", intra, true);
  private_nh.param("inter", inter, true);

  nodelet::Loader loader(private_nh);
  const ros::M_string remappings = ros::names::getRemappings();
  const std::vector<std::string> no_argv;
  const std::string ns = ros::this_node::getNamespace() == "/" ? "/" : ros::this_node::getNamespace() + "/";

  struct Stage {
    std::string name, type;
    bool on;
  };
  const std::vector<Stage> stages = {{"ret3d_detector", "ret3d/DetectorNodelet", detector},
                                     {"ret3d_intra", "ret3d/IntraRMNodelet", intra},
                                     {"ret3d_tracker", "ret3d/TrackerNodelet", true},
                                     {"ret3d_inter", "ret3d/InterRMNodelet", true},
                                     {"ret3d_markers", "ret3d/MarkerNodelet", true}};
  if (!inter) ros::param::set(ns + "ret3d_inter/passthrough", true);
  for (const Stage& s : stages) {
    if (!s.on) continue;
    ros::M_string remap = remappings;
    if (s.name == "ret3d_tracker" && !intra) {
      const std::string detections = ros::names::resolve("detections");
      remap[ros::names::resolve("detections_intra")] = remap.count(detections) ? remap.at(detections) : detections;
    }
    if (!loader.load(ns + s.name, s.type, remap, no_argv)) {
      ROS_FATAL("ret3d_node: %s (%s) did not start; see the message above", s.name.c_str(), s.type.c_str());
      return 1;
    }
  }
  ROS_INFO("ret3d_node: pipeline running (detector %s, IntraRM %s, InterRM %s)", detector ? "on" : "off",
           intra ? "on" : "off", inter ? "on" : "refining off (pass-through)");
  ros::spin();
  return 0;
}
