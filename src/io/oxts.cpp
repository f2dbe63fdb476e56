// KITTI OXTS (GPS/IMU) records, 30 values per line, and their conversion to LiDAR poses as the KITTI raw devkit does
// (convertOxtsToPose.m).
#include <algorithm>
#include <cmath>

#include "ret3d/io/kitti.h"
#include "rigid.h"
#include "text_fields.h"

namespace ret3d {
namespace kitti {
namespace {

constexpr const char* kOxtsFields[30] = {
    "lat", "lon", "alt", "roll", "pitch", "yaw", "vn", "ve", "vf", "vl", "vu", "ax", "ay", "az", "af",
    "al", "au", "wx", "wy", "wz", "wf", "wl", "wu", "pos_accuracy", "vel_accuracy", "navstat", "numsats", "posmode",
    "velmode", "orimode"};

constexpr double kEarthRadius = 6378137.0;  // WGS84 equatorial radius, as the devkit

}  // namespace

std::vector<OxtsRecord> readOxts(const std::string& path) {
  std::vector<OxtsRecord> records;
  detail::forEachLine(path, [&](const auto& fields, const detail::Where& where) {
    const auto v = detail::parseNumberRow(fields, where, kOxtsFields, 30, "an OXTS record");
    OxtsRecord r;
    std::copy(v.begin(), v.end(), r.values.begin());
    records.push_back(r);
  });
  return records;
}

void writeOxts(const std::string& path, const std::vector<OxtsRecord>& records) {
  std::string s;
  for (const auto& r : records) {
    for (int i = 0; i < 30; ++i) {
      if (i) s += ' ';
      detail::appendScientific(s, r.values[i], 15);  // latitude needs ~1e-9 degrees (1 mm)
    }
    s += '\n';
  }
  detail::writeText(path, s);
}

std::vector<Eigen::Isometry3d> oxtsToLidarPoses(const std::vector<OxtsRecord>& records, const Calibration& calib) {
  std::vector<Eigen::Isometry3d> out;
  if (records.empty()) return out;
  // Mercator projection with the scale of the first latitude (devkit latToScale / latlonToMercator).
  const double scale = std::cos(records.front().lat() * M_PI / 180.0);
  const auto imuPose = [&](const OxtsRecord& r) {
    const double mx = scale * r.lon() * M_PI * kEarthRadius / 180.0;
    const double my = scale * kEarthRadius * std::log(std::tan((90.0 + r.lat()) * M_PI / 360.0));
    Eigen::Isometry3d t = Eigen::Isometry3d::Identity();
    t.translation() = Eigen::Vector3d(mx, my, r.alt());
    // R = Rz(yaw) * Ry(pitch) * Rx(roll): the IMU's x forward, y left, z up; yaw 0 = east, counter-clockwise.
    t.linear() = (Eigen::AngleAxisd(r.yaw(), Eigen::Vector3d::UnitZ()) *
                  Eigen::AngleAxisd(r.pitch(), Eigen::Vector3d::UnitY()) *
                  Eigen::AngleAxisd(r.roll(), Eigen::Vector3d::UnitX()))
                     .toRotationMatrix();
    return t;
  };
  // T_velo0_velo_t = Tr_imu_to_velo * T_imu0_imu_t * Tr_imu_to_velo^-1.
  const Eigen::Isometry3d velo_from_imu = detail::nearestIsometry(calib.imu_to_velo.matrix());
  const Eigen::Isometry3d imu_from_velo = velo_from_imu.inverse(Eigen::Isometry);
  const Eigen::Isometry3d first_inv = imuPose(records.front()).inverse(Eigen::Isometry);
  out.reserve(records.size());
  for (const auto& r : records) out.push_back(velo_from_imu * first_inv * imuPose(r) * imu_from_velo);
  return out;
}

}  // namespace kitti
}  // namespace ret3d
