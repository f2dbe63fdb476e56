// KITTI-layout data -> ROS bag, and a bag validator (cartographer_ros' rosbag_validate, for our topics).
//
// A converted bag holds, per frame, stamped start_time + frame / rate:
//   /points               sensor_msgs/PointCloud2 in the velodyne driver layout, frame `sensor_frame`
//   /tf                   tf2_msgs/TFMessage: fixed_frame -> base_frame from the sequence's LiDAR poses (identity when
//                         the data has none)
//   /ground_truth/objects ret3d/Object3DArray in `sensor_frame`, when the data has labels (an empty array for a
//                         labelled frame without objects)
// and once, at the start, latched: /tf_static base_frame -> sensor_frame (z = sensor_height).
// Frames: `fixed_frame` coincides with `base_frame` at the sequence's first pose (frame 0), so the LiDAR pose P_t
// (T_velo0_velo_t) becomes T_fixed_base_t = S * P_t * S^-1, with S the static base -> sensor transform.
#pragma once

#include <cstddef>
#include <functional>
#include <string>
#include <vector>

namespace ret3d {

struct ConvertOptions {
  std::string sequence;  // tracking layout: SSSS to convert (default: the first sequence with scans)
  double rate = 10.0;    // Hz; frame f is stamped start_time + f / rate
  std::string fixed_frame = "odom";
  std::string base_frame = "base_link";
  std::string sensor_frame = "velodyne";
  double sensor_height = 1.73;  // m, base_frame -> sensor_frame (KITTI's HDL-64E mount)
  // Stamp of frame 0, in seconds. Any fixed value > 0 (ros::Time(0) means "latest" to tf); fixed so that converting
  // the same data twice gives the same bag.
  double start_time = 1.0e9;
  // Called after each frame with (frames done, frames total).
  std::function<void(std::size_t, std::size_t)> progress;
};

// Converts a KITTI tracking layout (ROOT[/training]/velodyne/SSSS/...; the sequence from options), a KITTI object
// layout (ROOT[/training]/velodyne/NNNNNN.bin, with label_2 and calib when present) or a plain folder of NNNNNN.bin
// scans (frames in file-name order) into `out_bag`. Ground truth: Car, Pedestrian and Cyclist labels (Van,
// Person_sitting, DontCare and the rest skipped), as LiDAR-frame boxes with num_points counted in the scan.
// Returns the number of frames written. Throws std::runtime_error (or kitti::ParseError) naming the problem: no
// scans, an unknown sequence, labels without a calibration, fewer poses than frames, options out of range.
std::size_t convertKittiToBag(const std::string& dataset_dir, const std::string& out_bag,
                              const ConvertOptions& options = {});

struct TopicSummary {
  std::string topic;
  std::string datatype;
  std::size_t count = 0;
  double first_stamp = 0, last_stamp = 0;  // bag (receive) times of the first and last message, s
};

struct CheckReport {
  std::string bag;
  std::vector<TopicSummary> topics;  // sorted by name
  double duration = 0;               // bag end - bag start, s
  std::size_t clouds = 0;
  std::size_t min_points = 0, max_points = 0;  // per cloud, after dropping non-finite points
  std::vector<std::string> problems;           // each makes the bag unusable for ret3d; empty = valid
  std::size_t problems_not_listed = 0;         // problems beyond the first 50 are only counted
  std::vector<std::string> notes;              // worth knowing, not wrong (e.g. no ground truth)

  bool ok() const { return problems.empty() && problems_not_listed == 0; }
  // Plain text: one line per topic (count, type, stamp range), duration, cloud sizes, notes, then problems or "OK".
  std::string summary() const;
};

// Validates a bag for ret3d: /points present as sensor_msgs/PointCloud2 with fields x, y, z and an intensity field
// (intensity, i or reflectivity) and a well-formed layout; known topics with the right types (/tf, /tf_static
// tf2_msgs/TFMessage, /ground_truth/objects ret3d/Object3DArray); header stamps strictly increasing on /points and
// /ground_truth/objects and non-decreasing per child frame on /tf; and for every cloud a transform chain
// fixed_frame -> the cloud's frame at the cloud's stamp (tf2 over all of /tf and /tf_static). Throws
// std::runtime_error when the file cannot be opened as a bag.
CheckReport checkBag(const std::string& bag, const std::string& fixed_frame = "odom");

}  // namespace ret3d
