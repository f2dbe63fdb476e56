// ret3d/IntraRMNodelet: detections -> IntraRM (Ret3D §3.2) -> detections_intra. A frame the module cannot take (e.g.
// featureless detections for a model trained with features) passes through unrefined, with a throttled warning.
#include <pluginlib/class_list_macros.hpp>

#include "ret3d/DetectionArray.h"
#include "ret3d/relation/intra_rm.h"
#include "ret3d/ros/detection_array.h"
#include "ret3d/ros/nodelets.h"

namespace ret3d {

class IntraRMNodelet : public StageNodelet<ret3d::DetectionArray> {
 public:
  ~IntraRMNodelet() override { stopWorker(); }

 private:
  void setup() override {
    const IntraRMNodeletParams params = loadIntraRMNodeletParams(getPrivateNodeHandle());
    intra_ = constructStage(getPrivateNodeHandle(), "model_path", params.intra.model_path,
                            [&] { return std::make_unique<relation::IntraRM>(params.intra); });
    publisher_ = getNodeHandle().advertise<ret3d::DetectionArray>("detections_intra", 1);
    start("detections");
  }

  void process(const ret3d::DetectionArray::ConstPtr& msg) override {
    const Detections in = toDetections(*msg);
    Detections out;
    try {
      out = intra_->refine(in);
    } catch (const std::exception& e) {
      degraded("refine_failed", std::string("IntraRM skipped, detections passed through unrefined: ") + e.what());
      out = in;
    }
    publisher_.publish(toDetectionArrayMsg(out, msg->header));
  }

  std::unique_ptr<relation::IntraRM> intra_;
  ros::Publisher publisher_;
};

}  // namespace ret3d

PLUGINLIB_EXPORT_CLASS(ret3d::IntraRMNodelet, nodelet::Nodelet)
