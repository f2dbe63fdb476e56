// ret3d/InterRMNodelet: tracked -> InterRM (Ret3D §3.3) -> objects (Object3DArray).
//
// InterRM needs each track's past boxes, but as a separate nodelet it only sees the `tracked` messages, not the
// tracker's internal histories. So it keeps its own TrackHistory per track id, fed from those messages: each tracked
// box is stored in the fixed frame (tf2, as the tracker does) and the sequence handed to InterRM is the history moved
// into the current sensor frame, newest first. Histories of ids not seen for more than ~max_age frames are dropped
// (the tracker's own max_age: such an id never returns); a stamp going backwards (bag loop) clears them all. Boxes
// without a track id pass through unrefined; so does the whole frame if the module refuses it (throttled warning).
// With ~passthrough (launch inter:=false) no model is loaded and every frame is published unrefined: the stage is off
// but `objects` still comes out (a remap cannot bridge `tracked` to `objects`, their message types differ).
#include <pluginlib/class_list_macros.hpp>

#include <algorithm>
#include <unordered_map>

#include "ret3d/DetectionArray.h"
#include "ret3d/Object3DArray.h"
#include "ret3d/core/transform.h"
#include "ret3d/relation/inter_rm.h"
#include "ret3d/ros/conversions.h"
#include "ret3d/ros/nodelets.h"
#include "ret3d/tracking/track_history.h"

namespace ret3d {

class InterRMNodelet : public StageNodelet<ret3d::DetectionArray> {
 public:
  ~InterRMNodelet() override { stopWorker(); }

 private:
  void setup() override {
    params_ = loadInterRMNodeletParams(getPrivateNodeHandle());
    if (!params_.passthrough) {
      inter_ = constructStage(getPrivateNodeHandle(), "model_path", params_.inter.model_path,
                              [&] { return std::make_unique<relation::InterRM>(params_.inter); });
    }
    if (inter_) capacity_ = static_cast<std::size_t>(std::max(1, inter_->arch().max_history));
    poses_ = std::make_unique<PoseSource>(params_.pose, getNodeHandle());
    publisher_ = getNodeHandle().advertise<ret3d::Object3DArray>("objects", 1);
    start("tracked");
  }

  void process(const ret3d::DetectionArray::ConstPtr& msg) override {
    if (!inter_) {
      publisher_.publish(ret3d::Object3DArrayPtr(new ret3d::Object3DArray(toMsg(fromMsgs(*msg), msg->header))));
      return;
    }
    const double stamp = msg->header.stamp.toSec();
    if (has_stamp_ && stamp < last_stamp_) {
      degraded("stamp_backwards", "stamp went backwards (" + std::to_string(last_stamp_) + " -> " +
                                      std::to_string(stamp) + "): " + std::to_string(histories_.size()) +
                                      " track histories cleared");
      histories_.clear();
    }
    has_stamp_ = true;
    last_stamp_ = stamp;
    ++frame_;

    const PoseSource::Result pose = poses_->lookup(msg->header.frame_id, msg->header.stamp);
    if (!pose.found) {
      degraded("no_transform", "no transform " + msg->header.frame_id + " -> " + poses_->fixedFrame() + " (" +
                                   pose.problem + "): histories kept with the last pose found");
    }

    std::vector<Box> boxes = fromMsgs(*msg);

    std::vector<relation::InterRMSequence> sequences;
    std::vector<std::size_t> sequence_box;  // index in boxes of each sequence's current box
    for (std::size_t i = 0; i < boxes.size(); ++i) {
      const Box& b = boxes[i];
      if (b.track_id == 0) continue;
      auto it = histories_.find(b.track_id);
      if (it == histories_.end()) it = histories_.emplace(b.track_id, Entry(capacity_)).first;
      it->second.last_frame = frame_;
      TrackHistory& history = it->second.history;
      if (!history.empty() && history.newest().stamp >= stamp) history.clear();  // one entry per stamp
      history.push(transformBox(b, pose.sensor_to_fixed), stamp);
      const std::vector<TimedBox> past = history.inSensorFrame(stamp, pose.sensor_to_fixed);  // oldest first
      relation::InterRMSequence seq;
      seq.boxes.reserve(past.size());
      seq.dt.reserve(past.size());
      seq.boxes.push_back(b);  // the current box exactly as tracked (not through the round trip to the fixed frame)
      seq.dt.push_back(0.0);
      for (std::size_t k = past.size() - 1; k-- > 0;) {
        seq.boxes.push_back(past[k].box);
        seq.dt.push_back(past[k].dt);
      }
      sequences.push_back(std::move(seq));
      sequence_box.push_back(i);
    }
    for (auto it = histories_.begin(); it != histories_.end();) {
      if (frame_ - it->second.last_frame > static_cast<std::uint64_t>(params_.max_age)) {
        it = histories_.erase(it);
      } else {
        ++it;
      }
    }

    if (!sequences.empty()) {
      try {
        const std::vector<Box> refined = inter_->refine(sequences);
        for (std::size_t s = 0; s < refined.size(); ++s) boxes[sequence_box[s]] = refined[s];
      } catch (const std::exception& e) {
        degraded("refine_failed", std::string("InterRM skipped, tracked boxes passed through unrefined: ") + e.what());
      }
    }
    ret3d::Object3DArrayPtr out(new ret3d::Object3DArray(toMsg(boxes, msg->header)));
    publisher_.publish(out);
  }

  static std::vector<Box> fromMsgs(const ret3d::DetectionArray& msg) {
    std::vector<Box> boxes;
    boxes.reserve(msg.objects.size());
    for (const auto& o : msg.objects) boxes.push_back(fromMsg(o));
    return boxes;
  }

  struct Entry {
    TrackHistory history;
    std::uint64_t last_frame = 0;
    explicit Entry(std::size_t capacity) : history(capacity) {}
  };

  InterRMNodeletParams params_;
  std::unique_ptr<relation::InterRM> inter_;
  std::unique_ptr<PoseSource> poses_;
  ros::Publisher publisher_;
  std::size_t capacity_ = 30;
  std::unordered_map<std::uint32_t, Entry> histories_;
  std::uint64_t frame_ = 0;
  bool has_stamp_ = false;
  double last_stamp_ = 0.0;
};

}  // namespace ret3d

PLUGINLIB_EXPORT_CLASS(ret3d::InterRMNodelet, nodelet::Nodelet)
