// ret3d/DetectorNodelet: points (PointCloud2 of any layout) -> LWD-3D Detector -> detections (DetectionArray with the
// per-object features). The previous sweep is kept for LWD-3D's two-sweep input; its motion to the current sweep
// comes from tf2 (both sensor poses in the fixed frame). Every cloud is answered with a DetectionArray unless the
// latest-frame policy or ~max_input_age drops it (StageNodelet). What the nodelet works around, it says (throttled)
// and counts on /diagnostics as degraded.<kind>: a cloud without intensity (conversion) or with NaN points
// (nonfinite_points), more points than ~max_points (over_point_limit: thinned evenly, not dropped), an empty
// (empty) or malformed (malformed) cloud (empty detections published), a missing transform (no_transform: previous
// sweep used without motion compensation), stamps going backwards (stamp_backwards), a gap longer than
// ~max_sweep_gap (sweep_gap) or a changed frame id (frame_changed): previous sweep not used; no transform from the
// sensor to ~base_frame (no_base_transform: the ego box placed with KITTI's mount).
#include <chrono>
#include <cmath>
#include <mutex>

#include <boost/thread/recursive_mutex.hpp>
#include <dynamic_reconfigure/server.h>
#include <pluginlib/class_list_macros.hpp>
#include <sensor_msgs/PointCloud2.h>

#include <optional>

#include "ret3d/DetectionArray.h"
#include "ret3d/DetectorConfig.h"
#include "ret3d/detector/detector.h"
#include "ret3d/ros/conversions.h"
#include "ret3d/ros/detection_array.h"
#include "ret3d/ros/nodelets.h"

namespace ret3d {

class DetectorNodelet : public StageNodelet<sensor_msgs::PointCloud2> {
 public:
  ~DetectorNodelet() override { stopWorker(); }

 private:
  void setup() override {
    params_ = loadDetectorNodeletParams(getPrivateNodeHandle());
    detector_ = constructStage(getPrivateNodeHandle(), "model_path", params_.detector.inference.model_path,
                               [&] { return std::make_unique<Detector>(params_.detector); });
    warmUp();
    startReconfigure();
    poses_ = std::make_unique<PoseSource>(params_.pose, getNodeHandle());
    publisher_ = getNodeHandle().advertise<ret3d::DetectionArray>("detections", 1);
    start("points");
  }

  // The first inferences of a freshly loaded network are several times slower (allocations, thread pools, BLAS
  // set-up): run them now on a synthetic scan of the usual size, so the first real clouds are not late.
  void warmUp() {
    PointCloud cloud;
    cloud.points.reserve(120000);
    for (int i = 0; i < 120000; ++i) {
      const double a = 2 * M_PI * (i % 2000) / 2000.0, r = 3.0 + 0.5 * (i / 2000);
      cloud.points.push_back({static_cast<float>(r * std::cos(a)), static_cast<float>(r * std::sin(a)),
                              static_cast<float>(-1.7 + 0.01 * (i % 7)), 0.3f});
    }
    const auto t0 = std::chrono::steady_clock::now();
    for (int k = 0; k < 3; ++k) detector_->detect(cloud, &cloud, Eigen::Isometry3d::Identity());
    NODELET_INFO_STREAM("detector warmed up in "
                        << std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count()
                        << " s (3 synthetic scans of 120k points); grid "
                        << detector_->describeGrids());
  }

  // dynamic_reconfigure (cfg/Detector.cfg): the score threshold and the NMS IoU change between clouds. The server
  // starts from the values the nodelet was configured with, not from the .cfg defaults. A value the detector's
  // options refuse (InferenceOptions::validate, whose ranges the .cfg's repeat) changes nothing: a warning says why
  // and the server reports the values in force.
  void startReconfigure() {
    reconfigure_ = std::make_unique<dynamic_reconfigure::Server<ret3d::DetectorConfig>>(reconfigure_mutex_,
                                                                                        getPrivateNodeHandle());
    ret3d::DetectorConfig start;
    start.score_threshold = params_.detector.inference.score_threshold;
    start.nms_iou = params_.detector.inference.nms_iou;
    reconfigure_->updateConfig(start);
    reconfigure_->setCallback([this](ret3d::DetectorConfig& c, std::uint32_t) {
      std::lock_guard<std::mutex> lock(detector_mutex_);
      try {
        detector_->setThresholds(c.score_threshold, c.nms_iou);
        NODELET_INFO_STREAM("detector thresholds: score_threshold " << c.score_threshold << ", nms_iou " << c.nms_iou);
      } catch (const OptionError& e) {
        const InferenceOptions& kept = detector_->options().inference;
        NODELET_WARN_STREAM("dynamic_reconfigure refused: " << e.what() << "; keeping score_threshold "
                                                            << kept.score_threshold << ", nms_iou " << kept.nms_iou);
        c.score_threshold = kept.score_threshold;
        c.nms_iou = kept.nms_iou;
      }
    });
  }

  void process(const sensor_msgs::PointCloud2::ConstPtr& msg) override {
    const double stamp = msg->header.stamp.toSec();
    Detections empty;
    empty.feature_dim = static_cast<std::size_t>(detector_->featureDim());

    CloudConversionReport report;
    PointCloud cloud;
    try {
      cloud = toCloud(*msg, params_.cloud, &report);
    } catch (const std::exception& e) {
      degraded("malformed", std::string("malformed cloud, no detections for it: ") + e.what());
      publisher_.publish(toDetectionArrayMsg(empty, msg->header));
      return;
    }
    for (const std::string& w : report.warnings) {
      degraded("conversion", "cloud: " + w, "conversion: " + w.substr(0, 20));
    }
    if (report.thinned) {
      degraded("over_point_limit", "cloud of " + std::to_string(report.input_points) + " points (> ~max_points " +
                                       std::to_string(params_.cloud.max_points) + "): thinned evenly, " +
                                       std::to_string(report.output_points) + " points kept");
    }
    if (report.dropped_nonfinite > 0) {
      degraded("nonfinite_points", "dropped " + std::to_string(report.dropped_nonfinite) + " of " +
                                       std::to_string(report.input_points) + " points with a NaN or Inf coordinate");
    }
    if (cloud.empty()) {
      degraded("empty", "empty cloud (after dropping invalid points): no detections");
      publisher_.publish(toDetectionArrayMsg(empty, msg->header));
      return;
    }

    const PoseSource::Result pose = poses_->lookup(msg->header.frame_id, msg->header.stamp);
    const PointCloud* previous = nullptr;
    Eigen::Isometry3d prev_to_current = Eigen::Isometry3d::Identity();
    if (previous_) {
      const double gap = stamp - previous_->stamp;
      if (gap <= 0.0) {
        degraded("stamp_backwards", "stamp went backwards or repeated (" + std::to_string(previous_->stamp) + " -> " +
                                        std::to_string(stamp) + "): previous sweep dropped");
      } else if (gap > params_.max_sweep_gap) {
        degraded("sweep_gap", "previous sweep " + std::to_string(gap) + " s old (> ~max_sweep_gap): not used");
      } else if (previous_->frame_id != msg->header.frame_id) {
        degraded("frame_changed", "frame id changed from " + previous_->frame_id + ": previous sweep dropped");
      } else {
        previous = &previous_->cloud;
        if (pose.found && previous_->pose_found) {
          prev_to_current = pose.sensor_to_fixed.inverse() * previous_->sensor_to_fixed;
        } else {
          degraded("no_transform", "no transform " + msg->header.frame_id + " -> " + poses_->fixedFrame() + " at " +
                                       std::to_string(stamp) + " (" + (pose.found ? "previous sweep" : pose.problem) +
                                       "): previous sweep used without motion compensation");
        }
      }
    }

    Detections detections;
    {
      std::lock_guard<std::mutex> lock(detector_mutex_);  // thresholds may change from the reconfigure thread
      placeEgoBox(msg->header.frame_id);
      detections = detector_->detect(cloud, previous, prev_to_current);
    }
    publisher_.publish(toDetectionArrayMsg(detections, msg->header));

    if (!previous_) previous_.emplace();
    previous_->cloud = std::move(cloud);
    previous_->stamp = stamp;
    previous_->frame_id = msg->header.frame_id;
    previous_->sensor_to_fixed = pose.sensor_to_fixed;
    previous_->pose_found = pose.found;
  }

  // The ego box lies in ~base_frame: the sensor's mount in it from tf, once per sensor frame (a static transform);
  // until tf has it, KITTI's mount (defaultSensorToBase), said and counted.
  void placeEgoBox(const std::string& sensor_frame) {
    if (!detector_->options().inference.ego_box || mounted_frame_ == sensor_frame) return;
    std::string problem;
    if (const auto mount = poses_->latest(params_.base_frame, sensor_frame, &problem)) {
      detector_->setSensorToBase(*mount);
      mounted_frame_ = sensor_frame;
      NODELET_INFO_STREAM("ego box " << detector_->options().inference.ego_box->describe() << " in "
                                     << params_.base_frame << ", sensor frame " << sensor_frame << " from tf");
      return;
    }
    detector_->setSensorToBase(defaultSensorToBase());
    degraded("no_base_transform", "no transform " + sensor_frame + " -> " + params_.base_frame + " (" + problem +
                                      "): the ego box placed with the sensor 1.73 m above " + params_.base_frame);
  }

  struct Sweep {
    PointCloud cloud;
    double stamp = 0.0;
    std::string frame_id;
    Eigen::Isometry3d sensor_to_fixed = Eigen::Isometry3d::Identity();
    bool pose_found = false;
  };

  DetectorNodeletParams params_;
  std::unique_ptr<Detector> detector_;
  std::unique_ptr<PoseSource> poses_;
  ros::Publisher publisher_;
  std::optional<Sweep> previous_;
  std::string mounted_frame_;  // the sensor frame whose mount in ~base_frame the detector holds
  std::mutex detector_mutex_;
  boost::recursive_mutex reconfigure_mutex_;
  std::unique_ptr<dynamic_reconfigure::Server<ret3d::DetectorConfig>> reconfigure_;
};

}  // namespace ret3d

PLUGINLIB_EXPORT_CLASS(ret3d::DetectorNodelet, nodelet::Nodelet)
