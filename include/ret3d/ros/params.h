// Parameters of the pipeline nodelets: one plain struct per nodelet, built by one function from the ROS parameter
// server (config/ret3d.yaml loaded with rosparam by launch/ret3d.launch), and validated there. An invalid value throws
// ParamError naming the parameter, its value and what is allowed; the nodelet then refuses to start. Where a stage
// has its own option loader and validation (tracker, detector, relation model files), it is reused, not repeated.
#pragma once

#include <ros/node_handle.h>
#include <xmlrpcpp/XmlRpcValue.h>

#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include "ret3d/detector/detector_options.h"
#include "ret3d/relation/inter_rm.h"
#include "ret3d/relation/intra_rm.h"
#include "ret3d/ros/conversions.h"
#include "ret3d/ros/markers.h"
#include "ret3d/tracking/tracker_options.h"

namespace ret3d {

class ParamError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// Typed reads of a node handle's parameters with defaults and ranges. Every failure throws ParamError
// "parameter <ns>/<name> = <value>: <what is allowed>".
class ParamReader {
 public:
  explicit ParamReader(const ros::NodeHandle& nh) : nh_(nh) {}
  std::string string(const std::string& name, const std::string& fallback) const;
  // Non-empty string.
  std::string nonEmpty(const std::string& name, const std::string& fallback) const;
  // One of `allowed`.
  std::string choice(const std::string& name, const std::string& fallback, const std::vector<std::string>& allowed) const;
  double number(const std::string& name, double fallback, double min, double max) const;  // inclusive range
  int integer(const std::string& name, int fallback, int min, int max) const;
  // The same in the range an options struct keeps for the value (e.g. InferenceOptions::kNmsIou).
  double number(const std::string& name, double fallback, const OptionRange& range) const;
  int integer(const std::string& name, int fallback, const OptionRange& range) const;
  bool boolean(const std::string& name, bool fallback) const;
  std::vector<double> numbers(const std::string& name, const std::vector<double>& fallback) const;  // a list
  bool has(const std::string& name) const { return nh_.hasParam(name); }
  // The full name of a parameter, for messages ("/ret3d_tracker/max_age").
  std::string fullName(const std::string& name) const { return nh_.resolveName(name); }
  // A dictionary parameter as YAML text (for a stage's own YAML loader); empty when the parameter is absent.
  std::string yaml(const std::string& name) const;

 private:
  ros::NodeHandle nh_;
};

// A parameter value (any XmlRpc type) as YAML text.
std::string toYaml(const XmlRpc::XmlRpcValue& value);

// The package's share folder (ros::package::getPath("ret3d")), for the default config and model paths; empty when
// the package cannot be found.
std::string packagePath();
// Default model files: $(find ret3d)/models/lwd3d/{detector,intra_rm,inter_rm}.pt.
std::string defaultModelPath(const std::string& file_name);

// The nodelets' parameter file (one section per node name), relative to the package.
inline constexpr const char* kNodeletParams = "config/ret3d.yaml";
// Its ret3d_detector/score_threshold in the package at `package_dir` (checked against InferenceOptions'
// range), for the offline pipeline (pipeline::PipelineConfig::params_score_threshold); nullopt without the file or
// the key. The same value the launch file gives the detector nodelet as ~score_threshold.
std::optional<double> nodeletParamsScoreThreshold(const std::string& package_dir);

// What every stage that needs the sensor's pose shares.
struct PoseParams {
  std::string fixed_frame = "odom";
  double tf_timeout = 0.05;  // s to wait for a transform at the cloud's stamp
};

// What every stage nodelet shares (read by StageNodelet::start, include/ret3d/ros/nodelets.h).
struct StageParams {
  // s: a frame whose stamp is older than this when the stage's worker takes it is dropped (dropped.too_old) instead
  // of answered late. 0 (the default): never; a bag played without --clock and use_sim_time has old stamps.
  double max_input_age = 0.0;
};

struct DetectorNodeletParams {
  DetectorOptions detector;          // ~model_path with ~config (YAML file; empty: the config stored in the model
                                     // file), then ~threads, ~score_threshold, ~nms_iou, ~nms_voting_iou,
                                     // ~iou_score_power, ~max_detections
  CloudConversionOptions cloud;      // ~intensity_scaling (auto|datatype|observed_max|fixed), ~intensity_scale,
                                     // ~max_points (500000; a bigger cloud is thinned to this many points)
  PoseParams pose;
  double max_sweep_gap = 0.25;       // s: an older previous sweep is not used (LWD-3D's second sweep is 0.1 s back)
  // ~ego_box ([x_min, x_max, y_min, y_max, z_min, z_max] in ~base_frame; [] = off; default the model's, KITTI's car)
  // lies in this frame; the sensor's pose in it comes from tf (KITTI's mount while tf has none).
  std::string base_frame = "base_link";
};
struct IntraRMNodeletParams {
  relation::IntraRMOptions intra;    // ~model_path, ~threads
};
struct TrackerNodeletParams {
  TrackerOptions tracker;            // ~tracker (inline dictionary) or ~tracker_config (YAML file)
  PoseParams pose;
};
struct InterRMNodeletParams {
  relation::InterRMOptions inter;    // ~model_path, ~threads
  bool passthrough = false;          // ~passthrough: no model, tracked boxes published unrefined (stage off)
  // ~publish_detections: the objects also as vision_msgs/Detection3DArray on objects/detections (ros/detection3d.h)
  bool publish_detections = true;
  PoseParams pose;
  // The tracker's options, from the tracker nodelet's own parameters (its tracker_config or inline tracker; the
  // nodelet named by ~tracker_node, default "ret3d_tracker", a sibling of this one): histories of track ids not seen
  // for more than tracker.max_age frames are dropped, since a track that coasts longer never comes back with that id.
  TrackerOptions tracker;
  // Non-empty: ~max_age is set, which is no longer read (the nodelet logs this warning).
  std::string ignored_warning;
};
struct MarkerNodeletParams {
  MarkerOptions markers;
  PoseParams pose;
};

StageParams loadStageParams(const ros::NodeHandle& private_nh);
DetectorNodeletParams loadDetectorNodeletParams(const ros::NodeHandle& private_nh);
IntraRMNodeletParams loadIntraRMNodeletParams(const ros::NodeHandle& private_nh);
TrackerNodeletParams loadTrackerNodeletParams(const ros::NodeHandle& private_nh);
// Reads the tracker's options from the tracker nodelet's parameters with loadTrackerNodeletParams (its namespace:
// ~tracker_node resolved in private_nh's parent namespace).
InterRMNodeletParams loadInterRMNodeletParams(const ros::NodeHandle& private_nh);
MarkerNodeletParams loadMarkerNodeletParams(const ros::NodeHandle& private_nh);

}  // namespace ret3d
