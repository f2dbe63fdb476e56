#include "ret3d/pipeline/stage_layout.h"

#include <array>
#include <stdexcept>

#include "ret3d/core/enum_names.h"

namespace ret3d {
namespace pipeline {

const std::vector<StageLayout>& pipelineLayout() {
  static const std::vector<StageLayout> kLayout = {
      {"ret3d_detector", "ret3d/DetectorNodelet", "base", "points", "detections", "detector", WhenOff::LeftToOthers},
      {"ret3d_intra", "ret3d/IntraRMNodelet", "intra", "detections", "detections_intra", "intra", WhenOff::Bridged},
      {"ret3d_tracker", "ret3d/TrackerNodelet", "track", "detections_intra", "tracked", "", WhenOff::AlwaysOn},
      {"ret3d_inter", "ret3d/InterRMNodelet", "inter", "tracked", "objects", "inter", WhenOff::Passthrough},
      {"ret3d_markers", "ret3d/MarkerNodelet", "", "objects", "objects/markers", "", WhenOff::AlwaysOn},
  };
  return kLayout;
}

std::vector<std::string> offlineStageNames() {
  std::vector<std::string> names;
  for (const StageLayout& s : pipelineLayout())
    if (!s.offline.empty()) names.push_back(s.offline);
  return names;
}

std::string NodeletLoad::input() const {
  const auto it = remaps.find(stage->input);
  return it == remaps.end() ? stage->input : it->second;
}

std::vector<NodeletLoad> nodeletsToLoad(const std::map<std::string, bool>& switches) {
  for (const auto& [name, value] : switches) {
    bool known = false;
    for (const StageLayout& s : pipelineLayout()) known = known || (!s.switch_arg.empty() && s.switch_arg == name);
    if (!known) throw std::invalid_argument("no pipeline stage is switched by '" + name + "'");
  }
  std::vector<NodeletLoad> out;
  std::map<std::string, std::string> bridged;  // output of a bridged stage -> the topic that replaces it
  for (const StageLayout& s : pipelineLayout()) {
    const auto it = s.switch_arg.empty() ? switches.end() : switches.find(s.switch_arg);
    const bool on = it == switches.end() || it->second;
    if (!on && s.off == WhenOff::Bridged) {
      const auto up = bridged.find(s.input);
      bridged[s.output] = up == bridged.end() ? s.input : up->second;
    }
    if (!on && s.off != WhenOff::Passthrough) continue;
    NodeletLoad load;
    load.stage = &s;
    load.passthrough = !on;
    const auto b = bridged.find(s.input);
    if (b != bridged.end()) load.remaps[s.input] = b->second;
    out.push_back(std::move(load));
  }
  return out;
}

constexpr std::array<const char*, 4> kWhenOffNames = {"always on", "left to others", "bridged", "passthrough"};
static_assert(kWhenOffNames.size() == static_cast<std::size_t>(WhenOff::Passthrough) + 1);

std::string whenOffName(WhenOff off) { return enumName(off, kWhenOffNames); }

}  // namespace pipeline
}  // namespace ret3d
