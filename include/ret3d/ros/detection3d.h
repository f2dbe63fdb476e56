// Object3DArray -> vision_msgs/Detection3DArray: the tracked and refined objects in the standard message that ROS 1
// planners, fusion nodes, loggers and rviz plugins read (the InterRM nodelet's objects/detections).
//
// vision_msgs 0.0.2 (the ROS 1 noetic release; third_party/vision_msgs when the system has none). Per object, one
// Detection3D, in the order of Object3DArray::objects:
//   header                 the array's header (the input cloud's stamp and frame)
//   results                one ObjectHypothesisWithPose: id = the Object3D label constant (1 Car, 2 Pedestrian,
//                          3 Cyclist, 0 Unknown), score = the object's score, pose.pose = the box centre and yaw
//                          quaternion, pose.covariance all zero (not estimated)
//   bbox                   center = the same pose; size = (length, width, height), the box's own x, y, z axes
//   source_cloud           empty (the points are in the input cloud)
// The track id has no place in this interface (0.0.2's Detection3D has no id field; ObjectHypothesisWithPose::id
// is the class, which VisionInfo's database maps to names): consumers that need ids pair detections[i] with
// objects[i] of /objects at the same stamp. Velocity and num_points have no place either.
#pragma once

#include <vision_msgs/Detection3DArray.h>

#include "ret3d/Object3DArray.h"

namespace ret3d {

vision_msgs::Detection3D toDetection3D(const ret3d::Object3D& object, const std_msgs::Header& header);
vision_msgs::Detection3DArray toDetection3DArray(const ret3d::Object3DArray& objects);

}  // namespace ret3d
