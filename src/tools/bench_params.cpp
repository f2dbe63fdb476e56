// The nodelet bench's nodelets: their parameters (config/ret3d.yaml onto the parameter server, then the options) and
// their loading, in the layout of the one stage table (pipeline/stage_layout.h; tools/nodelet_bench_parts.h).
#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <iostream>
#include <sstream>
#include <stdexcept>

#include "ret3d/pipeline/stage_layout.h"
#include "ret3d/ros/params.h"
#include "tools/nodelet_bench_parts.h"

namespace ret3d {
namespace tools {
namespace bench {

namespace {

// config/ret3d.yaml onto the parameter server, as `rosparam load` with subst_value does in launch/ret3d.launch.
XmlRpc::XmlRpcValue toXmlRpc(const YAML::Node& n) {
  XmlRpc::XmlRpcValue v;
  if (n.IsMap()) {
    v = XmlRpc::XmlRpcValue();
    for (const auto& kv : n) {
      if (kv.second.IsNull()) continue;
      v[kv.first.as<std::string>()] = toXmlRpc(kv.second);
    }
  } else if (n.IsSequence()) {
    v.setSize(static_cast<int>(n.size()));
    for (std::size_t i = 0; i < n.size(); ++i) v[static_cast<int>(i)] = toXmlRpc(n[i]);
  } else {
    bool b;
    int i;
    double d;
    if (n.Tag() == "!") v = n.as<std::string>();  // quoted: a string whatever it looks like
    else if (YAML::convert<bool>::decode(n, b)) v = b;
    else if (YAML::convert<int>::decode(n, i)) v = i;
    else if (YAML::convert<double>::decode(n, d)) v = d;
    else v = n.as<std::string>();
  }
  return v;
}

}  // namespace

void loadParams(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw std::runtime_error(path + ": cannot read the nodelets' parameters (--params)");
  std::stringstream ss;
  ss << in.rdbuf();
  std::string text = ss.str();
  const std::string find = "$(find ret3d)";
  for (std::size_t pos = text.find(find); pos != std::string::npos; pos = text.find(find, pos))
    text.replace(pos, find.size(), packagePath());
  YAML::Node root;
  try {
    root = YAML::Load(text);
  } catch (const YAML::Exception& e) {
    throw std::runtime_error(path + ":" + std::to_string(e.mark.line + 1) + ": " + e.msg);
  }
  if (!root.IsMap()) throw std::runtime_error(path + ": a dictionary of nodelet sections expected");
  for (const auto& kv : root) ros::param::set("/" + kv.first.as<std::string>(), toXmlRpc(kv.second));
}

// The nodelets' parameters: the package's YAML, then what the options override.
void setNodeletParams(const NodeletBenchOptions& o, const std::string& params) {
  loadParams(params);
  ros::param::set("/ret3d_detector/model_path", o.detector_model);
  ros::param::set("/ret3d_detector/config", o.detector_config);
  ros::param::set("/ret3d_detector/threads", o.threads);
  if (o.score_threshold >= 0) ros::param::set("/ret3d_detector/score_threshold", o.score_threshold);
  if (!o.grid_extent.empty()) ros::param::set("/ret3d_detector/grid_extent", o.grid_extent);
  ros::param::set("/ret3d_intra/model_path", o.intra_model);
  ros::param::set("/ret3d_intra/threads", o.threads);
  if (!o.tracker_config.empty()) ros::param::set("/ret3d_tracker/tracker_config", o.tracker_config);
  ros::param::set("/ret3d_inter/model_path", o.inter_model);
  ros::param::set("/ret3d_inter/threads", o.threads);
  ros::param::set("/ret3d_inter/passthrough", false);
}

void checkOptions(const NodeletBenchOptions& o) {
  if (o.stages.empty() || o.stages.front() != "base")
    throw std::runtime_error("--stages must start with base: the nodelets are fed point clouds");
  if (o.rate <= 0) throw std::runtime_error("--rate must be > 0, not " + std::to_string(o.rate));
  if (o.loop_frames < 0) throw std::runtime_error("--loop-frames must be >= 0, not " + std::to_string(o.loop_frames));
  if (o.soak_every <= 0) throw std::runtime_error("--soak-every must be > 0, not " + std::to_string(o.soak_every));
  if (o.load < 0) throw std::runtime_error("--load must be >= 0, not " + std::to_string(o.load));
}

bool hasStage(const std::vector<Stage>& stages, const std::string& name) {
  return std::any_of(stages.begin(), stages.end(), [&](const Stage& s) { return s.name == name; });
}

// The nodelets of --stages in pipeline order, as launch/ret3d.launch loads them (the one stage table,
// pipeline/stage_layout.h) with the stages after the last one left out; InterRM brings the tracker it reads from.
// The markers are not a stage here (loadNodelets adds them).
std::vector<Stage> pipelineStages(const NodeletBenchOptions& o) {
  auto has = [&](const std::string& s) { return std::find(o.stages.begin(), o.stages.end(), s) != o.stages.end(); };
  std::map<std::string, bool> switches;
  for (const pipeline::StageLayout& s : pipeline::pipelineLayout())
    if (s.off == pipeline::WhenOff::Bridged) switches[s.switch_arg] = has(s.offline);
  std::vector<Stage> stages;
  for (const pipeline::NodeletLoad& n : pipeline::nodeletsToLoad(switches)) {
    const pipeline::StageLayout& s = *n.stage;
    if (s.offline.empty() || !(has(s.offline) || (s.offline == "track" && has("inter")))) continue;
    stages.push_back({s.offline, s.node, s.nodelet, "/" + n.input(), "/" + s.output, n.remaps});
  }
  return stages;
}

void loadNodelets(nodelet::Loader& loader, const std::vector<Stage>& stages, const NodeletBenchOptions& o) {
  std::cout << "bench: loading the nodelets into this process (the manager, " << o.manager_threads
            << " callback threads):";
  std::vector<Stage> load = stages;
  // The markers read InterRM's objects, as the launch file loads them.
  const auto& layout = pipeline::pipelineLayout();
  const auto markers = std::find_if(layout.begin(), layout.end(), [](const auto& s) { return s.offline.empty(); });
  if (o.markers && hasStage(stages, "inter")) load.push_back({"", markers->node, markers->nodelet, "", "", {}});
  for (const Stage& s : load) std::cout << " " << s.type;
  std::cout << std::endl;
  for (const Stage& s : load) {
    ros::M_string remap;
    // A stage left out is bridged as launch/ret3d.launch bridges it (intra:=false: the tracker reads detections).
    for (const auto& [from, to] : s.remaps) remap["/" + from] = "/" + to;
    if (!loader.load("/" + s.nodelet, s.type, remap, {}))
      throw std::runtime_error("nodelet " + s.nodelet + " (" + s.type + ") did not start; see the message above");
  }
}

}  // namespace bench
}  // namespace tools
}  // namespace ret3d
