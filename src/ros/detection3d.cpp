// Object3DArray -> vision_msgs/Detection3DArray (include/ret3d/ros/detection3d.h).
#include "ret3d/ros/detection3d.h"

namespace ret3d {

vision_msgs::Detection3D toDetection3D(const ret3d::Object3D& object, const std_msgs::Header& header) {
  vision_msgs::Detection3D d;
  d.header = header;
  vision_msgs::ObjectHypothesisWithPose h;
  h.id = object.label;
  h.score = object.score;
  h.pose.pose = object.pose;  // covariance stays zero: not estimated
  d.results.push_back(h);
  d.bbox.center = object.pose;
  d.bbox.size = object.dimensions;
  return d;
}

vision_msgs::Detection3DArray toDetection3DArray(const ret3d::Object3DArray& objects) {
  vision_msgs::Detection3DArray msg;
  msg.header = objects.header;
  msg.detections.reserve(objects.objects.size());
  for (const ret3d::Object3D& o : objects.objects) msg.detections.push_back(toDetection3D(o, objects.header));
  return msg;
}

}  // namespace ret3d
