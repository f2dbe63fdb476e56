// DetectionArray <-> Detections: the message that travels between the stage nodelets (boxes plus the detector's
// per-object feature rows) and the core type the stages take.
#pragma once

#include <std_msgs/Header.h>

#include "ret3d/DetectionArray.h"
#include "ret3d/core/detections.h"

namespace ret3d {

// Throws std::invalid_argument when features does not hold objects.size() x feature_dim values.
Detections toDetections(const ret3d::DetectionArray& msg);
ret3d::DetectionArrayPtr toDetectionArrayMsg(const Detections& detections, const std_msgs::Header& header);

}  // namespace ret3d
