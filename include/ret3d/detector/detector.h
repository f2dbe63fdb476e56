// The LWD-3D base detector's inference API, shared by the nodelet, the command line and the tests:
// BEV encoding, network, decoding, rotated NMS per class, and the per-object feature o_i (Ret3D §3.1).
// No libtorch here (pimpl), so including this header costs nothing.
#pragma once

#include <memory>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "ret3d/core/detections.h"
#include "ret3d/core/types.h"
#include "ret3d/detector/detector_options.h"

namespace ret3d {

namespace nn {
class DetectorModel;
}

// Wall time of each part of the last detect() call, milliseconds.
struct DetectorTimings {
  double bev_ms = 0, network_ms = 0, decode_ms = 0, nms_ms = 0, refine_ms = 0;
  double total() const { return bev_ms + network_ms + decode_ms + nms_ms + refine_ms; }
};

class Detector {
 public:
  // Loads options.inference.model_path, refusing a file whose model differs from options.model (the message lists
  // what differs); with an empty path the network is freshly initialised (tests). Sets torch's thread count. Throws
  // std::invalid_argument (OptionError naming the key) for options DetectorOptions::validate() refuses.
  explicit Detector(const DetectorOptions& options);
  // Wraps an existing model (training: validation with the model being trained); the options' model part must match.
  Detector(const DetectorOptions& options, std::shared_ptr<nn::DetectorModel> model);
  ~Detector();
  Detector(const Detector&) = delete;
  Detector& operator=(const Detector&) = delete;

  // previous may be null (first frame); a point p of the previous sweep lies at prev_to_current * p now.
  // Returns boxes in the current sensor frame (velocity in m/s, score, class) by descending score, and one feature
  // row per box (feature_dim = featureDim()): the BEV feature at the box centre.
  Detections detect(const PointCloud& current, const PointCloud* previous = nullptr,
                    const Eigen::Isometry3d& prev_to_current = Eigen::Isometry3d::Identity());

  const DetectorOptions& options() const { return options_; }
  // The sensor's pose in the vehicle's base_link, where inference.ego_box lies (default: defaultSensorToBase(),
  // KITTI's mount 1.73 m above the ground); the detector nodelet sets it from tf.
  void setSensorToBase(const Eigen::Isometry3d& sensor_to_base);
  const Eigen::Isometry3d& sensorToBase() const;
  // Changes the inference thresholds between calls (dynamic_reconfigure); throws OptionError, changing nothing, for a
  // value InferenceOptions::validate() refuses.
  void setThresholds(double score_threshold, double nms_iou);
  const DetectorTimings& lastTimings() const { return timings_; }
  int featureDim() const;
  std::int64_t parameterCount() const;  // both models' with a far field
  bool hasFarField() const;             // inference.far_field loaded
  // The grid(s) the networks run on: "x [-48, 48] y [-48, 48] z [-3, 1] res 0.25 (384 x 384)", with a far field
  // "... near field; far field FILE: x [-80, 80] ... (320 x 192) beyond 2 m inside the near field's edge".
  std::string describeGrids() const;
  nn::DetectorModel& model();

 private:
  struct Impl;
  DetectorOptions options_;
  std::unique_ptr<Impl> impl_;
  DetectorTimings timings_;
};

}  // namespace ret3d
