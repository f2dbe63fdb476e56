// What every ret3d stage nodelet shares (the nodelets themselves: src/ros/*_nodelet.cpp; topics: ARCHITECTURE.md).
//
// StageNodelet<In>: a latest-frame slot and one worker thread. The subscriber callback only puts the message into the
// slot (replacing a message still waiting there, counted as dropped.superseded), so the stage always works on the
// newest frame and never builds up delay; the worker converts, calls the stage, converts and publishes. Every message
// is accounted for (include/ret3d/ros/diagnostics.h): answered, superseded, too old (~max_input_age) or an error in
// the stage. Messages travel as boost::shared_ptr (zero-copy between nodelets of one manager). diagnostic_updater
// reports the StageMonitor at 1 Hz.
//
// PoseSource: the sensor's pose in the fixed frame at a cloud's stamp from tf2; when the transform is missing it
// degrades to the last pose it found for that frame (identity before the first), with a throttled warning.
#pragma once

#include <diagnostic_updater/diagnostic_updater.h>
#include <nodelet/nodelet.h>
#include <ros/ros.h>
#include <tf2_eigen/tf2_eigen.h>
#include <tf2_ros/buffer.h>
#include <tf2_ros/transform_listener.h>

#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <thread>

#include <Eigen/Geometry>

#include "ret3d/core/log.h"
#include "ret3d/ros/diagnostics.h"
#include "ret3d/ros/params.h"

namespace ret3d {

// The stages log through ret3d's one logger (stderr by default); inside ROS its lines belong in rosconsole (rosout,
// the launch screen, the tests' log checks).
inline void routeStageLogToRos() {
  setLogSink([](LogLevel level, const std::string& message) {
    switch (level) {
      case LogLevel::Debug: ROS_DEBUG_STREAM_NAMED("ret3d", message); break;
      case LogLevel::Info: ROS_INFO_STREAM_NAMED("ret3d", message); break;
      case LogLevel::Warn: ROS_WARN_STREAM_NAMED("ret3d", message); break;
      default: ROS_ERROR_STREAM_NAMED("ret3d", message); break;
    }
  });
}

class PoseSource {
 public:
  PoseSource(const PoseParams& params, const ros::NodeHandle& nh)
      : params_(params), buffer_(ros::Duration(30.0)), listener_(buffer_, nh) {}

  struct Result {
    Eigen::Isometry3d sensor_to_fixed = Eigen::Isometry3d::Identity();
    bool found = false;   // false: the fallback (last pose found, or identity)
    std::string problem;  // why not found
  };
  Result lookup(const std::string& sensor_frame, const ros::Time& stamp) {
    Result r;
    try {
      // Waited for in wall time: with use_sim_time a paused clock (a bag that ended) would otherwise never time out.
      const ros::WallTime deadline = ros::WallTime::now() + ros::WallDuration(params_.tf_timeout);
      while (!buffer_.canTransform(params_.fixed_frame, sensor_frame, stamp) && ros::WallTime::now() < deadline) {
        ros::WallDuration(0.002).sleep();
      }
      const geometry_msgs::TransformStamped t = buffer_.lookupTransform(params_.fixed_frame, sensor_frame, stamp);
      r.sensor_to_fixed = tf2::transformToEigen(t);
      r.found = true;
      last_[sensor_frame] = r.sensor_to_fixed;
    } catch (const tf2::TransformException& e) {
      r.problem = e.what();
      const auto it = last_.find(sensor_frame);
      if (it != last_.end()) r.sensor_to_fixed = it->second;
    }
    return r;
  }
  bool hasFallbackPose(const std::string& sensor_frame) const { return last_.count(sensor_frame) > 0; }
  // The newest transform from `sensor_frame` into `target_frame` (a static mount: base_link <- sensor), without
  // waiting; none when tf has none yet (`problem` says why).
  std::optional<Eigen::Isometry3d> latest(const std::string& target_frame, const std::string& sensor_frame,
                                          std::string* problem) {
    try {
      return tf2::transformToEigen(buffer_.lookupTransform(target_frame, sensor_frame, ros::Time(0)));
    } catch (const tf2::TransformException& e) {
      *problem = e.what();
      return std::nullopt;
    }
  }
  const std::string& fixedFrame() const { return params_.fixed_frame; }

 private:
  PoseParams params_;
  tf2_ros::Buffer buffer_;
  tf2_ros::TransformListener listener_;
  std::map<std::string, Eigen::Isometry3d> last_;  // per sensor frame (worker thread only)
};

template <typename In>
class StageNodelet : public nodelet::Nodelet {
 public:
  ~StageNodelet() override { stopWorker(); }

 protected:
  using InConstPtr = typename In::ConstPtr;

  // Reads the parameters, builds the stage, advertises, and ends with start(input topic). Whatever it throws stops
  // the nodelet from starting, with the message logged (FATAL) and passed on to the loader.
  virtual void setup() = 0;
  // The stage's work on one frame (worker thread): it publishes an output for every frame it returns from.
  // Exceptions are caught, logged throttled and counted as dropped.error.
  virtual void process(const InConstPtr& msg) = 0;

  void onInit() final {
    try {
      setup();
    } catch (const std::exception& e) {
      NODELET_FATAL_STREAM(getName() << " refuses to start: " << e.what());
      throw;
    }
  }

  // Called at the end of the subclass's onInit, after its parameters and stage are ready.
  void start(const std::string& input_topic) {
    stage_params_ = loadStageParams(getPrivateNodeHandle());
    routeStageLogToRos();
    ros::NodeHandle& nh = getNodeHandle();
    updater_.reset(new diagnostic_updater::Updater(nh, getPrivateNodeHandle(), getName()));
    updater_->setHardwareID("ret3d");
    updater_->add(getName() + ": frames", this, &StageNodelet::diagnose);
    diagnostics_timer_ = nh.createWallTimer(ros::WallDuration(1.0),
                                            [this](const ros::WallTimerEvent&) { updater_->force_update(); });
    worker_ = std::thread([this] { workerLoop(); });
    // The latest frame wins in the slot below, which counts what it replaces. The subscriber's own queue is deeper
    // than one on purpose: roscpp drops from a full queue without telling anyone, and onMessage is cheap, so this
    // queue only holds messages for the moment until the manager's callback threads run.
    subscriber_ = nh.subscribe<In>(input_topic, kSubscriberQueue, &StageNodelet::onMessage, this);
    NODELET_INFO_STREAM(getName() << ": listening on " << subscriber_.getTopic());
  }

  // Subclasses call this first in their destructor, so that process() never runs on a half-destroyed object.
  void stopWorker() {
    subscriber_.shutdown();
    diagnostics_timer_.stop();
    {
      std::lock_guard<std::mutex> lock(mutex_);
      stop_ = true;
    }
    cv_.notify_all();
    if (worker_.joinable()) worker_.join();
  }

  // A degradation the stage worked around on a frame it answers: counted under degraded.<kind> (snake_case),
  // reported on /diagnostics, logged throttled (every 5 s per kind, or per `throttle_key` when given).
  void degraded(const std::string& kind, const std::string& what, const std::string& throttle_key = "") {
    monitor_.degraded(kind, what);
    warnThrottled(throttle_key.empty() ? kind : throttle_key, what);
  }

  StageMonitor monitor_;

 private:
  static constexpr std::uint32_t kSubscriberQueue = 10;

  void warnThrottled(const std::string& key, const std::string& what) {
    const ros::WallTime now = ros::WallTime::now();
    auto it = last_warned_.find(key);
    if (it == last_warned_.end() || (now - it->second).toSec() >= 5.0) {
      last_warned_[key] = now;
      NODELET_WARN_STREAM(getName() << ": " << what);
    }
  }

  void drop(DropReason reason, const std::string& what) {
    monitor_.dropped(reason);
    warnThrottled(std::string("dropped.") + dropReasonName(reason), what);
  }

  void onMessage(const InConstPtr& msg) {
    monitor_.input();
    {
      std::lock_guard<std::mutex> lock(mutex_);
      // Not logged: under load this is the policy working, and /diagnostics says how often.
      if (pending_) monitor_.dropped(DropReason::Superseded);
      pending_ = msg;
    }
    cv_.notify_one();
  }

  // Too old to be worth an answer (~max_input_age > 0): how old, or a negative number.
  double tooOld(const ros::Time& stamp) const {
    if (stage_params_.max_input_age <= 0.0) return -1.0;
    const double age = (ros::Time::now() - stamp).toSec();
    return age > stage_params_.max_input_age ? age : -1.0;
  }

  void workerLoop() {
    for (;;) {
      InConstPtr msg;
      {
        std::unique_lock<std::mutex> lock(mutex_);
        cv_.wait(lock, [this] { return stop_ || pending_; });
        if (stop_) return;
        msg.swap(pending_);
      }
      const double age = tooOld(msg->header.stamp);
      if (age >= 0.0) {
        drop(DropReason::TooOld, "frame at " + std::to_string(msg->header.stamp.toSec()) + " is " +
                                     std::to_string(age) + " s old (> ~max_input_age " +
                                     std::to_string(stage_params_.max_input_age) + " s): dropped");
        continue;
      }
      const auto t0 = std::chrono::steady_clock::now();
      try {
        process(msg);
      } catch (const std::exception& e) {
        drop(DropReason::Error,
             std::string("frame at ") + std::to_string(msg->header.stamp.toSec()) + " not processed: " + e.what());
        continue;
      }
      const double ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
      monitor_.processed(ms, msg->header.stamp);
    }
  }

  void diagnose(diagnostic_updater::DiagnosticStatusWrapper& status) { monitor_.fill(status); }

  ros::Subscriber subscriber_;
  std::unique_ptr<diagnostic_updater::Updater> updater_;
  ros::WallTimer diagnostics_timer_;
  std::thread worker_;
  std::mutex mutex_;
  std::condition_variable cv_;
  InConstPtr pending_;
  bool stop_ = false;
  StageParams stage_params_;
  std::map<std::string, ros::WallTime> last_warned_;  // worker thread only
};

// Runs `make` (a stage constructor) and turns any failure into a ParamError naming the parameter that pointed at
// what failed (e.g. "~model_path = /x.pt: no such file").
template <typename F>
auto constructStage(const ros::NodeHandle& private_nh, const std::string& param, const std::string& value, F&& make)
    -> decltype(make()) {
  try {
    return make();
  } catch (const std::exception& e) {
    throw ParamError("parameter " + private_nh.resolveName(param) + " = '" + value + "': " + e.what());
  }
}

}  // namespace ret3d
