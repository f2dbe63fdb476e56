// ret3d/TrackerNodelet: detections_intra -> GreedyTracker in the fixed frame (tf2: sensor frame -> fixed frame at the
// cloud's stamp) -> tracked (the detections with track ids, same order, features kept).
// A missing transform degrades to the last pose found for the frame (identity before any: tracking then happens in
// the sensor frame, i.e. as if the vehicle stood still), with a throttled warning; never a crash.
#include <pluginlib/class_list_macros.hpp>

#include "ret3d/DetectionArray.h"
#include "ret3d/ros/detection_array.h"
#include "ret3d/ros/nodelets.h"
#include "ret3d/tracking/greedy_tracker.h"

namespace ret3d {

class TrackerNodelet : public StageNodelet<ret3d::DetectionArray> {
 public:
  ~TrackerNodelet() override { stopWorker(); }

 private:
  void setup() override {
    const TrackerNodeletParams params = loadTrackerNodeletParams(getPrivateNodeHandle());
    tracker_ = std::make_unique<GreedyTracker>(params.tracker);
    poses_ = std::make_unique<PoseSource>(params.pose, getNodeHandle());
    publisher_ = getNodeHandle().advertise<ret3d::DetectionArray>("tracked", 1);
    start("detections_intra");
  }

  void process(const ret3d::DetectionArray::ConstPtr& msg) override {
    const PoseSource::Result pose = poses_->lookup(msg->header.frame_id, msg->header.stamp);
    if (!pose.found) {
      degraded("no_transform", "no transform " + msg->header.frame_id + " -> " + poses_->fixedFrame() + " at " +
                                   std::to_string(msg->header.stamp.toSec()) + " (" + pose.problem +
                                   "): tracking with " +
                                   (poses_->hasFallbackPose(msg->header.frame_id) ? "the last pose found"
                                                                                  : "the sensor frame as fixed frame"));
    }
    const std::size_t resets = tracker_->numResets();
    const Detections tracked = tracker_->update(toDetections(*msg), msg->header.stamp.toSec(), pose.sensor_to_fixed);
    if (tracker_->numResets() != resets) {
      degraded("tracker_reset", "stamp went backwards or jumped at " + std::to_string(msg->header.stamp.toSec()) +
                                    ": tracker reset (track ids keep counting)");
    }
    publisher_.publish(toDetectionArrayMsg(tracked, msg->header));
  }

  std::unique_ptr<GreedyTracker> tracker_;
  std::unique_ptr<PoseSource> poses_;
  ros::Publisher publisher_;
};

}  // namespace ret3d

PLUGINLIB_EXPORT_CLASS(ret3d::TrackerNodelet, nodelet::Nodelet)
