// Ego poses in the KITTI odometry convention (pose/SSSS.txt: one row-major 3x4 camera-to-world matrix per frame),
// and their conversion to LiDAR poses.
#include "ret3d/io/kitti.h"
#include "rigid.h"
#include "text_fields.h"

namespace ret3d {
namespace kitti {
namespace {

constexpr const char* kPoseFields[12] = {"r11", "r12", "r13", "tx", "r21", "r22",
                                         "r23", "ty",  "r31", "r32", "r33", "tz"};

}  // namespace

std::vector<Eigen::Isometry3d> readPoses(const std::string& path) {
  std::vector<Eigen::Isometry3d> poses;
  detail::forEachLine(path, [&](const auto& fields, const detail::Where& where) {
    const auto v = detail::parseNumberRow(fields, where, kPoseFields, 12, "a 3x4 pose");
    Eigen::Isometry3d t = Eigen::Isometry3d::Identity();
    for (int i = 0; i < 12; ++i) t.matrix()(i / 4, i % 4) = v[i];
    poses.push_back(t);
  });
  return poses;
}

void writePoses(const std::string& path, const std::vector<Eigen::Isometry3d>& poses) {
  std::string s;
  for (const auto& t : poses) {
    for (int i = 0; i < 12; ++i) {
      if (i) s += ' ';
      detail::appendScientific(s, t.matrix()(i / 4, i % 4), 12);
    }
    s += '\n';
  }
  detail::writeText(path, s);
}

std::vector<Eigen::Isometry3d> cameraPosesToLidar(const std::vector<Eigen::Isometry3d>& cam_poses,
                                                  const Calibration& calib) {
  std::vector<Eigen::Isometry3d> out;
  if (cam_poses.empty()) return out;
  // KITTI odometry poses are those of the rectified left camera (their calib's Tr already includes R0_rect), so the
  // camera-from-LiDAR transform here is R0_rect * Tr_velo_to_cam, made exactly rigid.
  const Eigen::Isometry3d cam_from_velo = detail::nearestIsometry(calib.veloToRectMatrix());
  const Eigen::Isometry3d velo_from_cam = cam_from_velo.inverse(Eigen::Isometry);
  // Relative to the first pose, so the result starts at identity even when the file's first pose is not.
  const Eigen::Isometry3d first_inv = cam_poses.front().inverse(Eigen::Isometry);
  out.reserve(cam_poses.size());
  for (const auto& p : cam_poses) out.push_back(velo_from_cam * first_inv * p * cam_from_velo);
  return out;
}

}  // namespace kitti
}  // namespace ret3d
