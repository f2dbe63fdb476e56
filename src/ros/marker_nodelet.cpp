// ret3d/MarkerNodelet: objects -> objects/markers (MarkerArray, see include/ret3d/ros/markers.h). The sensor pose
// from tf only keeps the trails in place while the vehicle moves; without it the trails are drawn as if it stood still.
#include <pluginlib/class_list_macros.hpp>

#include "ret3d/Object3DArray.h"
#include "ret3d/ros/conversions.h"
#include "ret3d/ros/markers.h"
#include "ret3d/ros/nodelets.h"

namespace ret3d {

class MarkerNodelet : public StageNodelet<ret3d::Object3DArray> {
 public:
  ~MarkerNodelet() override { stopWorker(); }

 private:
  void setup() override {
    const MarkerNodeletParams params = loadMarkerNodeletParams(getPrivateNodeHandle());
    builder_ = MarkerBuilder(params.markers);
    poses_ = std::make_unique<PoseSource>(params.pose, getNodeHandle());
    publisher_ = getNodeHandle().advertise<visualization_msgs::MarkerArray>("objects/markers", 1);
    start("objects");
  }

  void process(const ret3d::Object3DArray::ConstPtr& msg) override {
    const PoseSource::Result pose = poses_->lookup(msg->header.frame_id, msg->header.stamp);
    if (!pose.found) {
      degraded("no_transform", "no transform " + msg->header.frame_id + " -> " + poses_->fixedFrame() + " (" +
                                   pose.problem + "): trails drawn without ego motion");
    }
    visualization_msgs::MarkerArrayPtr out(new visualization_msgs::MarkerArray(
        builder_.build(fromMsg(*msg), msg->header, pose.sensor_to_fixed)));
    publisher_.publish(out);
  }

  MarkerBuilder builder_;
  std::unique_ptr<PoseSource> poses_;
  ros::Publisher publisher_;
};

}  // namespace ret3d

PLUGINLIB_EXPORT_CLASS(ret3d::MarkerNodelet, nodelet::Nodelet)
