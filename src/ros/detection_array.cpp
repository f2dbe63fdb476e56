// DetectionArray <-> Detections (include/ret3d/ros/detection_array.h).
#include "ret3d/ros/detection_array.h"

#include "ret3d/ros/conversions.h"

namespace ret3d {

Detections toDetections(const ret3d::DetectionArray& msg) {
  Detections d;
  d.boxes.reserve(msg.objects.size());
  for (const auto& o : msg.objects) d.boxes.push_back(fromMsg(o));
  d.feature_dim = msg.feature_dim;
  d.features = msg.features;
  d.validate();
  return d;
}

ret3d::DetectionArrayPtr toDetectionArrayMsg(const Detections& detections, const std_msgs::Header& header) {
  ret3d::DetectionArrayPtr msg(new ret3d::DetectionArray);
  msg->header = header;
  msg->objects.reserve(detections.size());
  for (const Box& b : detections.boxes) msg->objects.push_back(toMsg(b));
  msg->feature_dim = static_cast<std::uint32_t>(detections.feature_dim);
  msg->features = detections.features;
  return msg;
}

}  // namespace ret3d
