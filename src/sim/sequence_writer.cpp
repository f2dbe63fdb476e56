#include "ret3d/sim/sequence_writer.h"

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <stdexcept>

namespace ret3d {
namespace sim {

namespace fs = std::filesystem;

Eigen::Isometry3d lidarToCamera(const kitti::Calibration& calib) {
  const Eigen::Matrix4d m = calib.veloToRectMatrix();
  Eigen::JacobiSVD<Eigen::Matrix3d> svd(m.topLeftCorner<3, 3>(), Eigen::ComputeFullU | Eigen::ComputeFullV);
  Eigen::Matrix3d R = svd.matrixU() * svd.matrixV().transpose();
  if (R.determinant() < 0) {
    Eigen::Matrix3d U = svd.matrixU();
    U.col(2) *= -1;
    R = U * svd.matrixV().transpose();
  }
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = R;
  T.translation() = m.topRightCorner<3, 1>();
  return T;
}

SequenceWriter::SequenceWriter(const std::string& root, const std::string& sequence, const kitti::Calibration& calib)
    : dir_(root + "/training"), seq_(sequence), calib_(calib) {
  for (const char* sub : {"label_02", "calib", "pose", "sim_info"}) fs::create_directories(dir_ + "/" + sub);
  fs::create_directories(dir_ + "/velodyne/" + seq_);
  info_ =
      "# ret3d sim ground truth, one line per labelled object and frame (docs/SIMULATOR.md). LiDAR frame, metres,\n"
      "# radians, m/s. track_id as in label_02. num_points: the object's own returns inside its box; rays: rays whose\n"
      "# first hit is the object; unoccluded: rays that would hit it alone; visible = rays / unoccluded;\n"
      "# cam_trunc: fraction of the mesh outside image 2 (1 = not in view); cam_visible: unblocked fraction of its image.\n"
      "# frame track_id class x y z length width height yaw vx vy num_points rays unoccluded visible cam_trunc "
      "cam_visible\n";
}

void SequenceWriter::writeFrame(int frame, const PointCloud& cloud, const std::vector<ObjectTruth>& truth,
                                const Eigen::Isometry3d& T_velo0_velo) {
  char name[32];
  std::snprintf(name, sizeof(name), "/%06d.bin", frame);
  kitti::writeVelodyne(dir_ + "/velodyne/" + seq_ + name, cloud);
  if (static_cast<int>(lidar_poses_.size()) != frame)
    throw std::runtime_error("SequenceWriter: frames must be written in order from 0 (got " + std::to_string(frame) + ")");
  lidar_poses_.push_back(T_velo0_velo);
  char line[512];
  for (const ObjectTruth& o : truth) {
    labels_.push_back(o.label);
    const Box& b = o.box;
    std::snprintf(line, sizeof(line), "%d %d %s %.4f %.4f %.4f %.4f %.4f %.4f %.5f %.3f %.3f %u %u %u %.4f %.4f %.4f\n",
                  frame, o.label.track_id, o.label.type.c_str(), b.x, b.y, b.z, b.length, b.width, b.height, b.yaw, b.vx,
                  b.vy, b.num_points, o.hits, o.unoccluded, o.visible_fraction, o.camera_truncation, o.camera_visible);
    info_ += line;
  }
}

void SequenceWriter::finish() {
  kitti::writeTrackingLabels(dir_ + "/label_02/" + seq_ + ".txt", labels_);
  kitti::writeCalibration(dir_ + "/calib/" + seq_ + ".txt", calib_);
  std::vector<Eigen::Isometry3d> cam = camera_poses_;
  if (cam.empty()) {
    const Eigen::Isometry3d Tr = lidarToCamera(calib_), Tr_inv = Tr.inverse();
    for (const auto& P : lidar_poses_) cam.push_back(Tr * P * Tr_inv);
  }
  kitti::writePoses(dir_ + "/pose/" + seq_ + ".txt", cam);
  std::ofstream f(dir_ + "/sim_info/" + seq_ + ".txt", std::ios::binary);
  if (!f) throw std::runtime_error("cannot write " + dir_ + "/sim_info/" + seq_ + ".txt");
  f << info_;
}

}  // namespace sim
}  // namespace ret3d
