#include "ret3d/ros/kitti_bag.h"

#include <geometry_msgs/TransformStamped.h>
#include <rosbag/bag.h>
#include <rosbag/view.h>
#include <sensor_msgs/PointCloud2.h>
#include <tf2/buffer_core.h>
#include <tf2_msgs/TFMessage.h>

#include <algorithm>
#include <boost/make_shared.hpp>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <limits>
#include <map>
#include <optional>
#include <set>
#include <sstream>
#include <stdexcept>

#include "ret3d/core/geometry.h"
#include "ret3d/io/kitti.h"
#include "ret3d/ros/bag_reader.h"
#include "ret3d/ros/conversions.h"

namespace fs = std::filesystem;

namespace ret3d {
namespace {

constexpr const char* kPointsTopic = "/points";
constexpr const char* kTfTopic = "/tf";
constexpr const char* kTfStaticTopic = "/tf_static";
constexpr const char* kGroundTruthTopic = "/ground_truth/objects";

// ---- conversion ----

// One frame to write: its scan, its stamp index, and its labels when it has any.
struct FramePlan {
  std::string scan_path;
  double index = 0;                                              // stamp = start_time + index / rate
  std::optional<std::vector<kitti::Label>> labels;               // nullopt: no ground truth for this frame
  std::optional<kitti::Calibration> calib;                       // set whenever labels are
  Eigen::Isometry3d lidar_pose = Eigen::Isometry3d::Identity();  // T_velo0_velo_t
};

struct ConversionPlan {
  std::string description;  // "tracking sequence 0003 of ...", for messages
  std::vector<FramePlan> frames;
};

bool hasEntries(const fs::path& dir, bool want_dirs, const std::string& ext = "") {
  std::error_code ec;
  if (!fs::is_directory(dir, ec)) return false;
  for (const auto& e : fs::directory_iterator(dir, ec)) {
    if (want_dirs ? e.is_directory(ec) : (e.is_regular_file(ec) && e.path().extension() == ext)) return true;
  }
  return false;
}

std::vector<std::string> binFilesSorted(const fs::path& dir) {
  std::vector<std::string> files;
  for (const auto& e : fs::directory_iterator(dir)) {
    if (e.is_regular_file() && e.path().extension() == ".bin") files.push_back(e.path().string());
  }
  std::sort(files.begin(), files.end());
  return files;
}

kitti::Calibration calibrationFor(const std::string& calib_path, const std::string& label_path) {
  std::error_code ec;
  if (!fs::is_regular_file(calib_path, ec)) {
    throw std::runtime_error("labels '" + label_path + "' need a calibration to become LiDAR boxes, but '" +
                             calib_path + "' does not exist");
  }
  return kitti::readCalibration(calib_path);
}

ConversionPlan planTracking(const std::string& root, const std::string& wanted_seq) {
  const kitti::TrackingDataset ds(root);
  std::vector<std::string> with_scans;
  for (const auto& s : ds.sequences()) {
    if (!ds.frames(s).empty()) with_scans.push_back(s);
  }
  if (with_scans.empty()) throw std::runtime_error("no sequence with scans in '" + ds.dir() + "/velodyne'");
  const std::string seq = wanted_seq.empty() ? with_scans.front() : wanted_seq;
  if (std::find(with_scans.begin(), with_scans.end(), seq) == with_scans.end()) {
    std::string list;
    for (const auto& s : with_scans) list += (list.empty() ? "" : " ") + s;
    throw std::runtime_error("sequence '" + seq + "' has no scans in '" + ds.dir() + "/velodyne' (sequences: " + list +
                             ")");
  }

  ConversionPlan plan;
  plan.description = "tracking sequence " + seq + " of " + ds.dir();
  const std::vector<int> frames = ds.frames(seq);
  const std::vector<Eigen::Isometry3d> poses = ds.lidarPoses(seq);
  if (!poses.empty() && static_cast<std::size_t>(frames.back()) >= poses.size()) {
    throw std::runtime_error("sequence " + seq + " has a scan for frame " + std::to_string(frames.back()) +
                             " but only " + std::to_string(poses.size()) + " poses (" + ds.posePath(seq) + " or " +
                             ds.oxtsPath(seq) + ")");
  }
  std::map<int, std::vector<kitti::Label>> labels_by_frame;
  std::optional<kitti::Calibration> calib;
  if (ds.hasLabels(seq)) {
    calib = calibrationFor(ds.calibPath(seq), ds.labelPath(seq));
    for (auto& l : kitti::readTrackingLabels(ds.labelPath(seq))) labels_by_frame[l.frame].push_back(std::move(l));
  }
  for (int f : frames) {
    FramePlan fp;
    fp.scan_path = ds.velodynePath(seq, f);
    fp.index = f;  // the frame number, so gaps in a sequence keep their time
    if (calib) {
      fp.labels = labels_by_frame[f];  // a labelled sequence's frame without a line has no objects
      fp.calib = calib;
    }
    if (!poses.empty()) fp.lidar_pose = poses[static_cast<std::size_t>(f)];
    plan.frames.push_back(std::move(fp));
  }
  return plan;
}

ConversionPlan planObject(const std::string& root) {
  const kitti::ObjectDataset ds(root);
  ConversionPlan plan;
  plan.description = "object layout " + ds.dir();
  std::error_code ec;
  for (const auto& frame : ds.frames()) {
    if (!fs::is_regular_file(ds.velodynePath(frame), ec)) continue;  // a label without a scan
    FramePlan fp;
    fp.scan_path = ds.velodynePath(frame);
    fp.index = static_cast<double>(plan.frames.size());
    if (fs::is_regular_file(ds.labelPath(frame), ec)) {
      fp.calib = calibrationFor(ds.calibPath(frame), ds.labelPath(frame));
      fp.labels = kitti::readObjectLabels(ds.labelPath(frame));
    }
    plan.frames.push_back(std::move(fp));
  }
  return plan;
}

ConversionPlan planScanFolder(const std::string& dir) {
  ConversionPlan plan;
  plan.description = "scan folder " + dir;
  for (const auto& path : binFilesSorted(dir)) {
    FramePlan fp;
    fp.scan_path = path;
    fp.index = static_cast<double>(plan.frames.size());
    plan.frames.push_back(std::move(fp));
  }
  return plan;
}

ConversionPlan makePlan(const std::string& dataset_dir, const ConvertOptions& opt) {
  std::error_code ec;
  if (!fs::is_directory(dataset_dir, ec))
    throw std::runtime_error("dataset folder '" + dataset_dir + "' does not exist");
  const fs::path training = fs::path(dataset_dir) / "training";
  const fs::path dir = fs::is_directory(training, ec) ? training : fs::path(dataset_dir);
  const fs::path velodyne = dir / "velodyne";
  ConversionPlan plan;
  if (hasEntries(velodyne, /*want_dirs=*/true)) {
    plan = planTracking(dataset_dir, opt.sequence);
  } else {
    if (!opt.sequence.empty()) {
      throw std::runtime_error("--sequence " + opt.sequence + " given, but '" + dataset_dir +
                               "' is not a tracking layout (no velodyne/SSSS folders)");
    }
    if (hasEntries(velodyne, false, ".bin")) {
      plan = planObject(dataset_dir);
    } else if (hasEntries(dataset_dir, false, ".bin")) {
      plan = planScanFolder(dataset_dir);
    }
  }
  if (plan.frames.empty()) {
    if (hasEntries(dir / "label_02", false, ".txt") || hasEntries(dir / "label_2", false, ".txt")) {
      throw std::runtime_error("no scans in '" + dataset_dir +
                               "': it has labels but no velodyne/ point clouds, and a bag needs clouds");
    }
    throw std::runtime_error("no scans in '" + dataset_dir +
                             "': expected [training/]velodyne/SSSS/NNNNNN.bin (tracking), [training/]velodyne/"
                             "NNNNNN.bin (object) or NNNNNN.bin files");
  }
  return plan;
}

geometry_msgs::TransformStamped toTransformMsg(const Eigen::Isometry3d& T, const std::string& parent,
                                               const std::string& child, const ros::Time& stamp) {
  geometry_msgs::TransformStamped t;
  t.header.stamp = stamp;
  t.header.frame_id = parent;
  t.child_frame_id = child;
  t.transform.translation.x = T.translation().x();
  t.transform.translation.y = T.translation().y();
  t.transform.translation.z = T.translation().z();
  // Estimated poses are not exactly orthonormal: take the nearest rotation's normalised quaternion.
  Eigen::Quaterniond q(T.linear());
  q.normalize();
  t.transform.rotation.x = q.x();
  t.transform.rotation.y = q.y();
  t.transform.rotation.z = q.z();
  t.transform.rotation.w = q.w();
  return t;
}

// The connection header rosbag play needs to re-publish a topic latched (as a live /tf_static is).
template <typename T>
boost::shared_ptr<ros::M_string> latchedConnectionHeader(const T& msg) {
  auto header = boost::make_shared<ros::M_string>();
  (*header)["type"] = ros::message_traits::datatype(msg);
  (*header)["md5sum"] = ros::message_traits::md5sum(msg);
  (*header)["message_definition"] = ros::message_traits::definition(msg);
  (*header)["callerid"] = "/ret3d_convert";
  (*header)["latching"] = "1";
  return header;
}

std::vector<Box> groundTruthBoxes(const FramePlan& fp, const PointCloud& cloud) {
  std::vector<Box> boxes;
  for (const auto& label : *fp.labels) {
    // DontCare, Van, Person_sitting, Truck, Tram, Misc: not one of the detected classes (KITTI benchmark practice).
    if (!classFromName(label.type)) continue;
    boxes.push_back(kitti::labelToBox(label, *fp.calib));
  }
  const std::vector<std::uint32_t> counts = countPointsInBoxes(boxes, cloud);
  for (std::size_t i = 0; i < boxes.size(); ++i) boxes[i].num_points = counts[i];
  return boxes;
}

}  // namespace

std::size_t convertKittiToBag(const std::string& dataset_dir, const std::string& out_bag, const ConvertOptions& opt) {
  if (!(opt.rate > 0.0) || !std::isfinite(opt.rate)) {
    throw std::runtime_error("rate must be a positive number of Hz (got " + std::to_string(opt.rate) + ")");
  }
  if (!(opt.start_time > 0.0) || opt.start_time > 4.0e9) {
    throw std::runtime_error("start_time must be in (0, 4e9] s (got " + std::to_string(opt.start_time) + ")");
  }
  if (opt.fixed_frame.empty() || opt.base_frame.empty() || opt.sensor_frame.empty() ||
      opt.fixed_frame == opt.base_frame || opt.base_frame == opt.sensor_frame || opt.fixed_frame == opt.sensor_frame) {
    throw std::runtime_error("fixed, base and sensor frames must be three different non-empty names");
  }
  const ConversionPlan plan = makePlan(dataset_dir, opt);

  const fs::path out_parent = fs::path(out_bag).parent_path();
  if (!out_parent.empty()) fs::create_directories(out_parent);
  rosbag::Bag bag;
  try {
    bag.open(out_bag, rosbag::bagmode::Write);
  } catch (const rosbag::BagException& e) {
    throw std::runtime_error("cannot write bag '" + out_bag + "': " + e.what());
  }

  const ros::Time start(opt.start_time);
  const Eigen::Isometry3d base_to_sensor(Eigen::Translation3d(0.0, 0.0, opt.sensor_height));
  tf2_msgs::TFMessage tf_static;
  tf_static.transforms.push_back(toTransformMsg(base_to_sensor, opt.base_frame, opt.sensor_frame, start));
  bag.write(kTfStaticTopic, start, tf_static, latchedConnectionHeader(tf_static));

  const std::size_t total = plan.frames.size();
  for (std::size_t i = 0; i < total; ++i) {
    const FramePlan& fp = plan.frames[i];
    const ros::Time stamp = start + ros::Duration(fp.index / opt.rate);
    const PointCloud cloud = kitti::readVelodyne(fp.scan_path);

    // fixed_frame = base_link at frame 0: T_fixed_base = S * P_t * S^-1 (see kitti_bag.h).
    const Eigen::Isometry3d fixed_to_base = base_to_sensor * fp.lidar_pose * base_to_sensor.inverse();
    tf2_msgs::TFMessage tf;
    tf.transforms.push_back(toTransformMsg(fixed_to_base, opt.fixed_frame, opt.base_frame, stamp));
    bag.write(kTfTopic, stamp, tf);

    std_msgs::Header header;
    header.stamp = stamp;
    header.frame_id = opt.sensor_frame;
    header.seq = static_cast<std::uint32_t>(i);
    bag.write(kPointsTopic, stamp, toPointCloud2(cloud, header));
    if (fp.labels) bag.write(kGroundTruthTopic, stamp, toMsg(groundTruthBoxes(fp, cloud), header));
    if (opt.progress) opt.progress(i + 1, total);
  }
  bag.close();
  return total;
}

// ---- checking ----

namespace {

class ProblemList {
 public:
  explicit ProblemList(CheckReport& report) : report_(report) {}
  void add(const std::string& problem) {
    if (report_.problems.size() < kMaxListed) {
      report_.problems.push_back(problem);
    } else {
      ++report_.problems_not_listed;
    }
  }

 private:
  static constexpr std::size_t kMaxListed = 50;
  CheckReport& report_;
};

std::string stampString(const ros::Time& t) {
  std::ostringstream oss;
  oss << std::fixed << std::setprecision(6) << t.toSec();
  return oss.str();
}

// A tf2 buffer call (setTransform, canTransform) that throws on a stamp decades from the buffer's (ros::Duration
// overflows inside tf2): false, with the exception's text in *why, instead of the throw.
template <class Call>
bool tfCall(Call&& call, std::string* why) {
  try {
    return call();
  } catch (const std::runtime_error& e) {
    *why = e.what();
    return false;
  }
}

// The `number`-th message of the bag (from 1) as an M; null, with the problem listed, when it is of another type or
// its bytes do not hold an M. The reading goes on with the next message.
template <class M>
boost::shared_ptr<M> readListed(const rosbag::MessageInstance& m, std::size_t number, ProblemList& problems) {
  try {
    const auto msg = readBagMessage<M>(m);
    if (!msg) problems.add(m.getTopic() + ": message cannot be read (md5sum mismatch)");
    return msg;
  } catch (const std::runtime_error& e) {
    problems.add("message " + std::to_string(number) + " of the bag, " + e.what());
    return nullptr;
  }
}

struct CloudSeen {
  std::size_t index;
  ros::Time stamp;
  std::string frame;
};

// Reads a bag message by message and lists what is wrong in the report: types, stamps, transforms, point fields.
class BagChecker {
 public:
  BagChecker(CheckReport& report, double duration)
      : report_(report),
        problems_(report),
        // tf2 keeps the whole bag: its cache must span the bag's duration.
        tf_buffer_(ros::Duration(std::max(10.0, duration + 10.0))) {}

  // A damaged chunk (bad compression) ends the reading with a problem rather than an exception: the report still
  // lists what came before it. A damaged message is listed, and the reading goes on (readListed).
  void read(rosbag::View& view) {
    std::size_t messages_read = 0;
    try {
      for (const rosbag::MessageInstance& m : view) {
        ++messages_read;
        if (!countAndCheckType(m)) continue;
        const std::string& topic = m.getTopic();
        if (topic == kTfTopic || topic == kTfStaticTopic) {
          transforms(m, messages_read);
        } else if (topic == kPointsTopic) {
          cloud(m, messages_read);
        } else if (topic == kGroundTruthTopic) {
          groundTruth(m, messages_read);
        }
      }
    } catch (const std::exception& e) {
      problems_.add("damaged bag: reading stopped (" + std::to_string(messages_read) + " messages read): " + e.what());
    }
    report_.clouds = clouds_.size();
  }

  // What the whole bag says: its topics, a transform for every cloud, ground truth without clouds.
  void finish(const std::string& fixed_frame) {
    for (const auto& [name, ts] : topics_) report_.topics.push_back(ts);
    if (!topics_.count(kPointsTopic)) {
      std::string others;
      for (const auto& [name, ts] : topics_) {
        if (ts.datatype == "sensor_msgs/PointCloud2") others += " " + name;
      }
      problems_.add(std::string("no ") + kPointsTopic + " topic" +
                    (others.empty() ? "" : " (PointCloud2 on:" + others + "; ret3d reads " + kPointsTopic + ")"));
    }
    // Every cloud must be placeable in the fixed frame at its own stamp (what the tracker does online).
    for (const CloudSeen& c : clouds_) {
      if (c.frame.empty() || c.frame == fixed_frame) continue;
      std::string error;
      if (!tfCall([&] { return tf_buffer_.canTransform(fixed_frame, c.frame, c.stamp, &error); }, &error)) {
        problems_.add("cloud " + std::to_string(c.index) + " (stamp " + stampString(c.stamp) + "): no transform " +
                      fixed_frame + " -> " + c.frame + " at its stamp: " + error);
      }
    }
    std::size_t gt_without_cloud = 0;
    for (double s : gt_stamps_) {
      if (!cloud_stamps_.count(s)) ++gt_without_cloud;
    }
    if (gt_without_cloud > 0) {
      report_.notes.push_back(std::to_string(gt_without_cloud) + " of " + std::to_string(gt_stamps_.size()) + " " +
                              kGroundTruthTopic + " messages have no cloud with the same stamp");
    }
    if (!topics_.count(kGroundTruthTopic)) {
      report_.notes.push_back(std::string("no ") + kGroundTruthTopic + ": fine for detection, not for evaluation");
    }
    if (!clouds_.empty() && report_.max_points == 0) report_.notes.push_back("every cloud is empty");
  }

 private:
  // Counts the message under its topic; false when the topic is not one ret3d reads or has another type (listed
  // once per topic).
  bool countAndCheckType(const rosbag::MessageInstance& m) {
    static const std::map<std::string, std::string> kExpectedTypes = {{kPointsTopic, "sensor_msgs/PointCloud2"},
                                                                      {kTfTopic, "tf2_msgs/TFMessage"},
                                                                      {kTfStaticTopic, "tf2_msgs/TFMessage"},
                                                                      {kGroundTruthTopic, "ret3d/Object3DArray"}};
    const std::string& topic = m.getTopic();
    TopicSummary& ts = topics_[topic];
    if (ts.count == 0) {
      ts.topic = topic;
      ts.datatype = m.getDataType();
      ts.first_stamp = m.getTime().toSec();
    }
    ++ts.count;
    ts.last_stamp = m.getTime().toSec();
    const auto expected = kExpectedTypes.find(topic);
    if (expected == kExpectedTypes.end()) return false;
    if (m.getDataType() != expected->second) {
      if (wrong_type_reported_.insert(topic).second) {
        problems_.add(topic + " has type " + m.getDataType() + ", expected " + expected->second);
      }
      return false;
    }
    return true;
  }

  // /tf and /tf_static: into the tf2 buffer; a dynamic transform going back in time or one tf2 rejects is listed.
  void transforms(const rosbag::MessageInstance& m, std::size_t number) {
    const std::string& topic = m.getTopic();
    const bool is_static = topic == kTfStaticTopic;
    const auto tf = readListed<tf2_msgs::TFMessage>(m, number, problems_);
    if (!tf) return;
    for (const auto& t : tf->transforms) {
      if (!is_static) {
        auto& last = last_tf_stamp_[t.child_frame_id];
        if (t.header.stamp < last) {
          problems_.add(topic + ": transform " + t.header.frame_id + " -> " + t.child_frame_id + " at " +
                        stampString(t.header.stamp) + " goes back in time (previous " + stampString(last) + ")");
        }
        last = t.header.stamp;
      }
      std::string why = "empty frame, NaN or self-transform";
      if (!tfCall([&] { return tf_buffer_.setTransform(t, "bag", is_static); }, &why)) {
        problems_.add(topic + ": transform " + t.header.frame_id + " -> " + t.child_frame_id + " at " +
                      stampString(t.header.stamp) + " rejected by tf2 (" + why + ")");
      }
    }
  }

  // A cloud: increasing stamps, a frame, x / y / z and an intensity field, readable by toCloud (its point count).
  void cloud(const rosbag::MessageInstance& m, std::size_t number) {
    const auto msg = readListed<sensor_msgs::PointCloud2>(m, number, problems_);
    if (!msg) return;
    const std::size_t index = clouds_.size();
    const std::string where = "cloud " + std::to_string(index) + " (stamp " + stampString(msg->header.stamp) + ")";
    if (index > 0 && msg->header.stamp <= last_cloud_stamp_) {
      problems_.add(where + ": stamp not after the previous cloud's " + stampString(last_cloud_stamp_));
    }
    last_cloud_stamp_ = msg->header.stamp;
    if (msg->header.frame_id.empty()) problems_.add(where + ": empty frame_id");
    std::set<std::string> names;
    for (const auto& f : msg->fields) names.insert(f.name);
    for (const char* f : {"x", "y", "z"}) {
      if (!names.count(f)) problems_.add(where + ": no field '" + std::string(f) + "'");
    }
    if (!names.count("intensity") && !names.count("i") && !names.count("reflectivity")) {
      problems_.add(where + ": no intensity field (intensity, i or reflectivity)");
    }
    try {
      const std::size_t n = toCloud(*msg).size();
      report_.min_points = sized_clouds_ == 0 ? n : std::min(report_.min_points, n);
      ++sized_clouds_;
      report_.max_points = std::max(report_.max_points, n);
    } catch (const std::invalid_argument& e) {
      if (names.count("x") && names.count("y") && names.count("z")) problems_.add(where + ": " + e.what());
    }
    clouds_.push_back({index, msg->header.stamp, msg->header.frame_id});
    cloud_stamps_.insert(msg->header.stamp.toSec());
  }

  // A ground-truth message: increasing stamps and a frame.
  void groundTruth(const rosbag::MessageInstance& m, std::size_t number) {
    const std::string& topic = m.getTopic();
    const auto msg = readListed<ret3d::Object3DArray>(m, number, problems_);
    if (!msg) return;
    const std::size_t gt_count = gt_stamps_.size();
    if (gt_count > 0 && msg->header.stamp <= last_gt_stamp_) {
      problems_.add(topic + " message " + std::to_string(gt_count) + " (stamp " + stampString(msg->header.stamp) +
                    "): stamp not after the previous one's " + stampString(last_gt_stamp_));
    }
    last_gt_stamp_ = msg->header.stamp;
    if (msg->header.frame_id.empty()) {
      problems_.add(topic + " message " + std::to_string(gt_count) + ": empty frame_id");
    }
    gt_stamps_.push_back(msg->header.stamp.toSec());
  }

  CheckReport& report_;
  ProblemList problems_;
  tf2::BufferCore tf_buffer_;
  std::map<std::string, TopicSummary> topics_;
  std::set<std::string> wrong_type_reported_;
  std::map<std::string, ros::Time> last_tf_stamp_;  // per child frame
  std::vector<CloudSeen> clouds_;
  std::set<double> cloud_stamps_;
  ros::Time last_cloud_stamp_, last_gt_stamp_;
  std::size_t sized_clouds_ = 0;
  std::vector<double> gt_stamps_;
};

}  // namespace

CheckReport checkBag(const std::string& path, const std::string& fixed_frame) {
  CheckReport report;
  report.bag = path;
  rosbag::Bag bag;
  openCheckedBag(bag, path);
  rosbag::View view(bag);
  const ros::Time begin = view.size() > 0 ? view.getBeginTime() : ros::Time();
  const ros::Time end = view.size() > 0 ? view.getEndTime() : ros::Time();
  report.duration = (end - begin).toSec();
  BagChecker checker(report, report.duration);
  checker.read(view);
  checker.finish(fixed_frame);
  return report;
}

std::string CheckReport::summary() const {
  std::ostringstream oss;
  oss << "bag: " << bag << "\n";
  oss << std::fixed << std::setprecision(3) << "duration: " << duration << " s\n";
  oss << "topics:\n";
  std::size_t width = 0;
  for (const auto& t : topics) width = std::max(width, t.topic.size());
  for (const auto& t : topics) {
    oss << "  " << std::left << std::setw(static_cast<int>(width)) << t.topic << std::right << std::setw(8) << t.count
        << " msgs  " << std::left << std::setw(26) << t.datatype << std::right << std::setprecision(3) << " "
        << t.first_stamp << " .. " << t.last_stamp << "\n";
  }
  oss << "clouds: " << clouds;
  if (clouds > 0) oss << ", " << min_points << " to " << max_points << " points each";
  oss << "\n";
  for (const auto& n : notes) oss << "note: " << n << "\n";
  if (ok()) {
    oss << "result: OK\n";
  } else {
    oss << "result: " << problems.size() + problems_not_listed << " problem(s)\n";
    for (const auto& p : problems) oss << "  - " << p << "\n";
    if (problems_not_listed > 0) oss << "  ... and " << problems_not_listed << " more\n";
  }
  return oss.str();
}

}  // namespace ret3d
