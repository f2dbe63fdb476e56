// Conversions between ROS messages and the core types: PointCloud2 <-> PointCloud, Object3D <-> Box.
// Free functions in the style of cartographer_ros' msg_conversion.h. They never log: whatever a caller should hear
// about (dropped points, a missing intensity field) goes into a CloudConversionReport, which the node layer logs
// throttled. Malformed input throws std::invalid_argument with a message naming the problem.
#pragma once

#include <sensor_msgs/PointCloud2.h>
#include <std_msgs/Header.h>

#include <cstddef>
#include <string>
#include <vector>

#include "ret3d/Object3D.h"
#include "ret3d/Object3DArray.h"
#include "ret3d/core/types.h"

namespace ret3d {

// How the raw intensity of a cloud becomes the core's [0, 1] intensity. Every rule clamps to [0, 1] at the end.
enum class IntensityScaling {
  // Integer fields by their datatype's range (uint8 / 255, uint16 / 65535, ...); float fields as they are when the
  // cloud's maximum is <= 1 (KITTI reflectance), otherwise divided by that maximum (velodyne 0-255, Ouster thousands).
  Auto,
  // Integer fields by their datatype's range; float fields taken as already in [0, 1].
  DatatypeRange,
  // Divided by the cloud's observed maximum, whatever the datatype (per-scan normalisation).
  ObservedMax,
  // Divided by CloudConversionOptions::intensity_scale (e.g. 255 for a driver that always emits 0-255 floats, which
  // keeps intensities comparable between scans, unlike the per-scan rules).
  FixedScale,
};

struct CloudConversionOptions {
  IntensityScaling intensity_scaling = IntensityScaling::Auto;
  double intensity_scale = 255.0;  // used by FixedScale only; must be > 0
  bool keep_time = true;           // fill PointCloud::time when the message has a time field
  bool keep_ring = true;           // fill PointCloud::ring when the message has a ring field
  // 0: no limit. A message with more points is thinned evenly by index (row by row, the same points every time) to
  // this many before conversion: CloudConversionReport::thinned says so.
  std::size_t max_points = 0;
};

// What toCloud found and did; filled when a report is passed.
struct CloudConversionReport {
  std::size_t input_points = 0;       // width * height
  std::size_t output_points = 0;      // after dropping non-finite points
  std::size_t dropped_nonfinite = 0;  // points with a NaN or Inf coordinate
  bool thinned = false;               // more than max_points: only max_points of the input points were read
  std::string intensity_field;        // "intensity", "i", "reflectivity", or empty when none
  std::string time_field;             // "time", "t", "timestamp", or empty
  bool has_ring = false;
  double intensity_divisor = 1.0;     // raw intensity / divisor = normalised intensity (before clamping)
  double raw_intensity_max = 0.0;     // largest finite raw intensity seen
  std::vector<std::string> warnings;  // e.g. "no intensity field: intensities set to 0"
};

// PointCloud2 of any layout -> core cloud. Fields are found by name: x, y, z; intensity from `intensity`, else `i`,
// else `reflectivity`; optional `ring`; optional time from `time`, else `t`, else `timestamp` (integer times are
// nanoseconds, float times seconds; absolute times - above 1e6 s - become offsets from the header stamp). Any
// numeric datatype, point_step and padding; is_bigendian respected; organized clouds (height > 1, row_step) read
// row by row. Points with a non-finite coordinate are dropped. Above options.max_points, an even selection of that
// many input points is converted.
// Throws std::invalid_argument when x, y or z is missing or the message is malformed (data shorter than its
// declared size, a field past point_step, an unknown datatype).
PointCloud toCloud(const sensor_msgs::PointCloud2& msg, const CloudConversionOptions& options = {},
                   CloudConversionReport* report = nullptr);

// Core cloud -> PointCloud2 in the velodyne driver's layout: x, y, z, intensity float32, ring uint16, time float32,
// packed (point_step 22), height 1, host byte order. Intensity stays in [0, 1]; ring and time are 0 when the cloud
// has none.
sensor_msgs::PointCloud2 toPointCloud2(const PointCloud& cloud, const std_msgs::Header& header);

// Box <-> Object3D: centre and yaw (as a quaternion about z) in pose, (length, width, height) in dimensions,
// (vx, vy, 0) in velocity, label constants equal to ObjectClass values.
ret3d::Object3D toMsg(const Box& box);
// Yaw is recovered from the quaternion's rotation about z and wrapped to (-pi, pi]; an unknown label becomes Unknown.
Box fromMsg(const ret3d::Object3D& msg);
ret3d::Object3DArray toMsg(const std::vector<Box>& boxes, const std_msgs::Header& header);
std::vector<Box> fromMsg(const ret3d::Object3DArray& msg);

}  // namespace ret3d
