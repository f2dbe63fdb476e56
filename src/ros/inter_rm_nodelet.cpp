// ret3d/InterRMNodelet: tracked -> InterRM (Ret3D §3.3) -> objects (Object3DArray).
//
// InterRM needs each track's past boxes, but as a separate nodelet it only sees the `tracked` messages: the
// sequences come from pipeline::TrackHistories fed with them (the same class the offline pipeline uses), with the
// sensor's pose from tf2 as the tracker has it, and histories ageing out after the tracker's max_age (its options read
// from the tracker nodelet's tracker_config, src/ros/params.cpp). Boxes without a track id pass through unrefined; so does the
// whole frame if the module refuses it (throttled warning). With ~passthrough (launch inter:=false) no model is loaded
// and every frame is published unrefined: the stage is off but `objects` still comes out (a remap cannot bridge
// `tracked` to `objects`, their message types differ). The same objects also go out as vision_msgs/Detection3DArray
// on objects/detections (ros/detection3d.h: class id, score, box; same stamp and frame) unless ~publish_detections is
// false; converted only while someone subscribes.
#include <pluginlib/class_list_macros.hpp>

#include <algorithm>

#include "ret3d/DetectionArray.h"
#include "ret3d/Object3DArray.h"
#include "ret3d/pipeline/track_histories.h"
#include "ret3d/relation/inter_rm.h"
#include "ret3d/ros/conversions.h"
#include "ret3d/ros/detection3d.h"
#include "ret3d/ros/nodelets.h"

namespace ret3d {

class InterRMNodelet : public StageNodelet<ret3d::DetectionArray> {
 public:
  ~InterRMNodelet() override { stopWorker(); }

 private:
  void setup() override {
    params_ = loadInterRMNodeletParams(getPrivateNodeHandle());
    if (!params_.ignored_warning.empty()) NODELET_WARN_STREAM(params_.ignored_warning);
    if (!params_.passthrough) {
      inter_ = constructStage(getPrivateNodeHandle(), "model_path", params_.inter.model_path,
                              [&] { return std::make_unique<relation::InterRM>(params_.inter); });
    }
    if (inter_) {
      histories_ = std::make_unique<pipeline::TrackHistories>(
          static_cast<std::size_t>(std::max(1, inter_->arch().max_history)), params_.tracker.max_age);
    }
    poses_ = std::make_unique<PoseSource>(params_.pose, getNodeHandle());
    publisher_ = getNodeHandle().advertise<ret3d::Object3DArray>("objects", 1);
    if (params_.publish_detections)
      detections_publisher_ = getNodeHandle().advertise<vision_msgs::Detection3DArray>("objects/detections", 1);
    start("tracked");
  }

  void process(const ret3d::DetectionArray::ConstPtr& msg) override {
    std::vector<Box> boxes = fromMsgs(*msg);
    if (inter_) {
      const PoseSource::Result pose = poses_->lookup(msg->header.frame_id, msg->header.stamp);
      if (!pose.found) {
        degraded("no_transform", "no transform " + msg->header.frame_id + " -> " + poses_->fixedFrame() + " (" +
                                     pose.problem + "): histories kept with the last pose found");
      }
      const std::size_t before = histories_->size();
      const pipeline::TrackHistories::Sequences s =
          histories_->update(boxes, msg->header.stamp.toSec(), pose.sensor_to_fixed);
      if (s.cleared) {
        degraded("stamp_backwards", "stamp went backwards (to " + std::to_string(msg->header.stamp.toSec()) +
                                        "): " + std::to_string(before) + " track histories cleared");
      }
      if (!s.sequences.empty()) {
        try {
          pipeline::applyRefined(s, inter_->refine(s.sequences), boxes);
        } catch (const std::exception& e) {
          degraded("refine_failed", std::string("InterRM skipped, tracked boxes passed through unrefined: ") + e.what());
        }
      }
    }
    const ret3d::Object3DArrayPtr objects(new ret3d::Object3DArray(toMsg(boxes, msg->header)));
    publisher_.publish(objects);
    if (detections_publisher_ && detections_publisher_.getNumSubscribers() > 0) {
      detections_publisher_.publish(
          vision_msgs::Detection3DArrayPtr(new vision_msgs::Detection3DArray(toDetection3DArray(*objects))));
    }
  }

  static std::vector<Box> fromMsgs(const ret3d::DetectionArray& msg) {
    std::vector<Box> boxes;
    boxes.reserve(msg.objects.size());
    for (const auto& o : msg.objects) boxes.push_back(fromMsg(o));
    return boxes;
  }

  InterRMNodeletParams params_;
  std::unique_ptr<relation::InterRM> inter_;
  std::unique_ptr<pipeline::TrackHistories> histories_;
  std::unique_ptr<PoseSource> poses_;
  ros::Publisher publisher_, detections_publisher_;
};

}  // namespace ret3d

PLUGINLIB_EXPORT_CLASS(ret3d::InterRMNodelet, nodelet::Nodelet)
