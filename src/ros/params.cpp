// Parameter loading and validation for the nodelets (include/ret3d/ros/params.h).
#include "ret3d/ros/params.h"

#include <ros/names.h>
#include <ros/package.h>

#include <filesystem>
#include <sstream>
#include <yaml-cpp/yaml.h>

#include "ret3d/core/yaml_reader.h"
#include "ret3d/detector/model_file.h"
#include "ret3d/pipeline/score_threshold.h"

namespace ret3d {
namespace {

std::string show(const XmlRpc::XmlRpcValue& v) {
  std::string s = toYaml(v);
  while (!s.empty() && s.back() == '\n') s.pop_back();
  return s;
}

void emit(YAML::Emitter& out, const XmlRpc::XmlRpcValue& v) {
  XmlRpc::XmlRpcValue& value = const_cast<XmlRpc::XmlRpcValue&>(v);  // XmlRpc's accessors are not const
  switch (value.getType()) {
    case XmlRpc::XmlRpcValue::TypeBoolean: out << static_cast<bool>(value); break;
    case XmlRpc::XmlRpcValue::TypeInt: out << static_cast<int>(value); break;
    case XmlRpc::XmlRpcValue::TypeDouble: out << static_cast<double>(value); break;
    case XmlRpc::XmlRpcValue::TypeString: out << static_cast<std::string>(value); break;
    case XmlRpc::XmlRpcValue::TypeArray:
      out << YAML::BeginSeq;
      for (int i = 0; i < value.size(); ++i) emit(out, value[i]);
      out << YAML::EndSeq;
      break;
    case XmlRpc::XmlRpcValue::TypeStruct:
      out << YAML::BeginMap;
      for (auto it = value.begin(); it != value.end(); ++it) {
        out << YAML::Key << it->first << YAML::Value;
        emit(out, it->second);
      }
      out << YAML::EndMap;
      break;
    default: out << YAML::Null; break;
  }
}

PoseParams loadPoseParams(const ParamReader& p) {
  PoseParams pose;
  pose.fixed_frame = p.nonEmpty("fixed_frame", pose.fixed_frame);
  pose.tf_timeout = p.number("tf_timeout", pose.tf_timeout, 0.0, 5.0);
  return pose;
}

}  // namespace

std::string toYaml(const XmlRpc::XmlRpcValue& value) {
  YAML::Emitter out;
  emit(out, value);
  return std::string(out.c_str()) + "\n";
}

std::string ParamReader::string(const std::string& name, const std::string& fallback) const {
  XmlRpc::XmlRpcValue v;
  if (!nh_.getParam(name, v)) return fallback;
  if (v.getType() != XmlRpc::XmlRpcValue::TypeString) {
    throw ParamError("parameter " + fullName(name) + " = " + show(v) + ": must be a string");
  }
  return static_cast<std::string>(v);
}

std::string ParamReader::nonEmpty(const std::string& name, const std::string& fallback) const {
  const std::string s = string(name, fallback);
  if (s.empty()) throw ParamError("parameter " + fullName(name) + " = '': must not be empty");
  return s;
}

std::string ParamReader::choice(const std::string& name, const std::string& fallback,
                                const std::vector<std::string>& allowed) const {
  const std::string s = string(name, fallback);
  for (const auto& a : allowed) {
    if (s == a) return s;
  }
  std::string list;
  for (const auto& a : allowed) list += (list.empty() ? "" : ", ") + a;
  throw ParamError("parameter " + fullName(name) + " = '" + s + "': must be one of " + list);
}

double ParamReader::number(const std::string& name, double fallback, double min, double max) const {
  return number(name, fallback, OptionRange{min, max});
}

// One format for every range: the options structs' own words (core/option_range.h).
double ParamReader::number(const std::string& name, double fallback, const OptionRange& range) const {
  XmlRpc::XmlRpcValue v;
  double x = fallback;
  if (nh_.getParam(name, v)) {
    if (v.getType() == XmlRpc::XmlRpcValue::TypeDouble) {
      x = static_cast<double>(v);
    } else if (v.getType() == XmlRpc::XmlRpcValue::TypeInt) {
      x = static_cast<int>(v);
    } else {
      throw ParamError("parameter " + fullName(name) + " = " + show(v) + ": must be a number; " + range.describe());
    }
  }
  if (!range.contains(x))
    throw ParamError("parameter " + fullName(name) + " = " + optionValueText(x) + ": " + range.describe());
  return x;
}

int ParamReader::integer(const std::string& name, int fallback, int min, int max) const {
  return integer(name, fallback, OptionRange{static_cast<double>(min), static_cast<double>(max)});
}

int ParamReader::integer(const std::string& name, int fallback, const OptionRange& range) const {
  XmlRpc::XmlRpcValue v;
  int x = fallback;
  if (nh_.getParam(name, v)) {
    if (v.getType() != XmlRpc::XmlRpcValue::TypeInt)
      throw ParamError("parameter " + fullName(name) + " = " + show(v) + ": must be an integer; " + range.describe());
    x = static_cast<int>(v);
  }
  if (!range.contains(x))
    throw ParamError("parameter " + fullName(name) + " = " + std::to_string(x) + ": " + range.describe());
  return x;
}

std::vector<double> ParamReader::numbers(const std::string& name, const std::vector<double>& fallback) const {
  XmlRpc::XmlRpcValue v;
  if (!nh_.getParam(name, v)) return fallback;
  const auto refuse = [&] { return ParamError("parameter " + fullName(name) + " = " + show(v) + ": must be a list of numbers"); };
  if (v.getType() != XmlRpc::XmlRpcValue::TypeArray) throw refuse();
  std::vector<double> out;
  for (int i = 0; i < v.size(); ++i) {
    XmlRpc::XmlRpcValue& e = v[i];
    if (e.getType() == XmlRpc::XmlRpcValue::TypeDouble) out.push_back(static_cast<double>(e));
    else if (e.getType() == XmlRpc::XmlRpcValue::TypeInt) out.push_back(static_cast<int>(e));
    else throw refuse();
  }
  return out;
}

bool ParamReader::boolean(const std::string& name, bool fallback) const {
  XmlRpc::XmlRpcValue v;
  if (!nh_.getParam(name, v)) return fallback;
  if (v.getType() != XmlRpc::XmlRpcValue::TypeBoolean) {
    throw ParamError("parameter " + fullName(name) + " = " + show(v) + ": must be true or false");
  }
  return static_cast<bool>(v);
}

std::string ParamReader::yaml(const std::string& name) const {
  XmlRpc::XmlRpcValue v;
  if (!nh_.getParam(name, v)) return "";
  if (v.getType() != XmlRpc::XmlRpcValue::TypeStruct) {
    throw ParamError("parameter " + fullName(name) + " = " + show(v) + ": must be a dictionary");
  }
  return toYaml(v);
}

std::string packagePath() { return ros::package::getPath("ret3d"); }

std::string defaultModelPath(const std::string& file_name) { return packagePath() + "/models/lwd3d/" + file_name; }

std::optional<double> nodeletParamsScoreThreshold(const std::string& package_dir) {
  const std::string path = (std::filesystem::path(package_dir) / kNodeletParams).string();
  if (package_dir.empty() || !std::filesystem::exists(path)) return std::nullopt;
  double v = 0;
  if (!YamlReader::load(path).child("ret3d_detector").get("score_threshold", &v, InferenceOptions::kScoreThreshold))
    return std::nullopt;
  return v;
}

StageParams loadStageParams(const ros::NodeHandle& private_nh) {
  const ParamReader p(private_nh);
  StageParams params;
  params.max_input_age = p.number("max_input_age", params.max_input_age, 0.0, 3600.0);
  return params;
}

DetectorNodeletParams loadDetectorNodeletParams(const ros::NodeHandle& private_nh) {
  const ParamReader p(private_nh);
  DetectorNodeletParams params;
  // An untrained network would publish noise: the nodelet always needs a model file.
  const std::string model_path = p.nonEmpty("model_path", defaultModelPath("detector.pt"));
  // ~config empty (the default): the config the model was trained with, stored in the model file, so an anchor-head
  // or a centre-head model runs as it is without naming its YAML. A YAML given must describe the file's model (the
  // detector checks it against the file when it loads the weights).
  const std::string config = p.string("config", "");
  try {
    params.detector = detectorOptionsForModel(model_path, config);
  } catch (const std::exception& e) {
    const std::string name = config.empty() ? "model_path" : "config";
    throw ParamError("parameter " + p.fullName(name) + " = '" + (config.empty() ? model_path : config) +
                     "': " + e.what());
  }
  // Each parameter is the inference option of its name, in the range InferenceOptions keeps for it.
  using I = InferenceOptions;
  InferenceOptions& inf = params.detector.inference;
  inf.threads = p.integer("threads", inf.threads, I::kThreads);
  // ~score_threshold: config/ret3d.yaml's value, or the launch file's / command line's (pipeline/score_threshold.h).
  const std::optional<double> score_threshold =
      p.has("score_threshold") ? std::optional<double>(p.number("score_threshold", 0, I::kScoreThreshold))
                               : std::nullopt;
  if (const std::optional<float> t = pipeline::chooseScoreThreshold(score_threshold, /*tracks=*/true, std::nullopt))
    inf.setScoreThreshold(*t);
  inf.candidate_threshold =
      static_cast<float>(p.number("candidate_threshold", inf.candidate_threshold, I::kCandidateThreshold));
  inf.nms_iou = p.number("nms_iou", inf.nms_iou, I::kNmsIou);
  inf.nms_voting_iou = p.number("nms_voting_iou", inf.nms_voting_iou, I::kNmsVotingIou);
  inf.iou_score_power = p.number("iou_score_power", inf.iou_score_power, I::kIouScorePower);
  // The model file's point refinement (boxes fitted to the raw returns) can only be switched off here.
  if (!p.boolean("point_refine", true)) inf.point_refine = PointRefineOptions();
  inf.max_detections = p.integer("max_detections", inf.max_detections, I::kMaxDetections);
  // The ground the network covers (a trained model runs on a wider grid at a cost in proportion to its area).
  try {
    if (p.has("grid_extent")) inf.grid_extent = GridExtent::fromValues(p.numbers("grid_extent", {}));
    if (p.has("ego_box")) {
      const std::vector<double> ego = p.numbers("ego_box", {});
      inf.ego_box = ego.empty() ? std::nullopt : std::optional<EgoBox>(EgoBox::fromValues(ego));
    }
    params.detector.validate();
  } catch (const OptionError& e) {
    // The parameters above were read in validate()'s ranges and the model's own options checked when it was read:
    // what is left to refuse is the grid extent or the ego box.
    for (const std::string key : {"grid_extent", "ego_box"})
      if (e.key() == key || e.key() == "inference." + key)
        throw ParamError("parameter " + p.fullName(key) + " = " + e.value() + ": " + e.reason());
    const std::string name = config.empty() ? "model_path" : "config";
    throw ParamError("parameter " + p.fullName(name) + " = '" + (config.empty() ? model_path : config) +
                     "': " + e.what());
  }
  const std::string scaling =
      p.choice("intensity_scaling", "auto", {"auto", "datatype", "observed_max", "fixed"});
  params.cloud.intensity_scaling = scaling == "auto"           ? IntensityScaling::Auto
                                   : scaling == "datatype"     ? IntensityScaling::DatatypeRange
                                   : scaling == "observed_max" ? IntensityScaling::ObservedMax
                                                               : IntensityScaling::FixedScale;
  params.cloud.intensity_scale = p.number("intensity_scale", params.cloud.intensity_scale, 1e-6, 1e9);
  // 500,000: twice a 128-beam scan, four times an HDL-64E's. Below a thousand points a scan is no longer a scan;
  // above 10 million one cloud takes seconds to convert alone.
  params.cloud.max_points = static_cast<std::size_t>(p.integer("max_points", 500000, 1000, 10000000));
  params.pose = loadPoseParams(p);
  params.max_sweep_gap = p.number("max_sweep_gap", params.max_sweep_gap, 0.0, 10.0);
  params.base_frame = p.nonEmpty("base_frame", params.base_frame);
  return params;
}

IntraRMNodeletParams loadIntraRMNodeletParams(const ros::NodeHandle& private_nh) {
  const ParamReader p(private_nh);
  IntraRMNodeletParams params;
  params.intra.model_path = p.nonEmpty("model_path", defaultModelPath("intra_rm.pt"));
  // libtorch's threads are process-wide: the detector's range.
  params.intra.threads = p.integer("threads", 2, InferenceOptions::kThreads);
  return params;
}

TrackerNodeletParams loadTrackerNodeletParams(const ros::NodeHandle& private_nh) {
  const ParamReader p(private_nh);
  TrackerNodeletParams params;
  // Inline (~tracker: {max_age: 5, ...}) or a file (~tracker_config); either way the tracker's own loader, which
  // refuses unknown keys and invalid values.
  const std::string inline_yaml = p.yaml("tracker");
  if (!inline_yaml.empty()) {
    try {
      params.tracker = parseTrackerOptions(inline_yaml);
    } catch (const std::exception& e) {
      throw ParamError("parameter " + p.fullName("tracker") + ": " + e.what());
    }
  } else {
    const std::string file = p.nonEmpty("tracker_config", packagePath() + "/config/tracker.yaml");
    try {
      params.tracker = loadTrackerOptions(file);
    } catch (const std::exception& e) {
      throw ParamError("parameter " + p.fullName("tracker_config") + " = '" + file + "': " + e.what());
    }
  }
  params.pose = loadPoseParams(p);
  return params;
}

InterRMNodeletParams loadInterRMNodeletParams(const ros::NodeHandle& private_nh) {
  const ParamReader p(private_nh);
  InterRMNodeletParams params;
  params.passthrough = p.boolean("passthrough", false);
  params.publish_detections = p.boolean("publish_detections", true);
  params.inter.model_path = p.nonEmpty("model_path", defaultModelPath("inter_rm.pt"));
  params.inter.threads = p.integer("threads", 2, InferenceOptions::kThreads);
  params.pose = loadPoseParams(p);
  if (params.passthrough) return params;  // no histories kept
  // The tracker's own options, from its tracker_config (or inline ~tracker) read as the tracker nodelet reads them:
  // the one home of max_age.
  const std::string tracker_node = p.nonEmpty("tracker_node", "ret3d_tracker");
  const ros::NodeHandle tracker_nh(ros::NodeHandle(ros::names::parentNamespace(private_nh.getNamespace())),
                                   tracker_node);
  params.tracker = loadTrackerNodeletParams(tracker_nh).tracker;
  if (p.has("max_age")) {
    params.ignored_warning = "parameter " + p.fullName("max_age") + " is no longer read (ignored): track histories " +
                             "follow the tracker's max_age " + std::to_string(params.tracker.max_age) + " (" +
                             tracker_nh.resolveName("tracker_config") + " or " + tracker_nh.resolveName("tracker") +
                             "); remove it";
  }
  return params;
}

MarkerNodeletParams loadMarkerNodeletParams(const ros::NodeHandle& private_nh) {
  const ParamReader p(private_nh);
  MarkerNodeletParams params;
  MarkerOptions& m = params.markers;
  m.trail_length = p.integer("trail_length", m.trail_length, MarkerOptions::kTrailLength);
  m.line_width = p.number("line_width", m.line_width, MarkerOptions::kLineWidth);
  m.text_size = p.number("text_size", m.text_size, MarkerOptions::kTextSize);
  m.min_arrow_speed = p.number("min_arrow_speed", m.min_arrow_speed, MarkerOptions::kMinArrowSpeed);
  m.arrow_seconds = p.number("arrow_seconds", m.arrow_seconds, MarkerOptions::kArrowSeconds);
  params.pose = loadPoseParams(p);
  return params;
}

}  // namespace ret3d
