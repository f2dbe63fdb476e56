// A tiny KITTI tracking sequence written by the tests themselves (convert_test, the bag_play rostest), so they need
// no downloaded data: known boxes, a known number of points inside each, known ego motion.
#pragma once

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <string>
#include <vector>

#include "ret3d/core/types.h"
#include "ret3d/io/kitti.h"

namespace ret3d {
namespace test {

// k^3 points strictly inside the box (a lattice at 10 % .. 90 % of each dimension).
inline void addLatticeInside(const Box& b, int k, float intensity, PointCloud& cloud) {
  const double c = std::cos(b.yaw), s = std::sin(b.yaw);
  for (int i = 0; i < k; ++i) {
    for (int j = 0; j < k; ++j) {
      for (int m = 0; m < k; ++m) {
        const double u = (0.1 + 0.8 * i / (k - 1) - 0.5) * b.length;
        const double v = (0.1 + 0.8 * j / (k - 1) - 0.5) * b.width;
        const double w = (0.1 + 0.8 * m / (k - 1) - 0.5) * b.height;
        cloud.points.push_back({static_cast<float>(b.x + c * u - s * v), static_cast<float>(b.y + s * u + c * v),
                                static_cast<float>(b.z + w), intensity});
      }
    }
  }
}

// A tiny KITTI tracking sequence: a car driving ahead (+0.5 m per frame) and a standing pedestrian, each filled with
// a lattice of points, on a ground grid 1.73 m below the sensor; a Van and a DontCare region in the labels (to be
// skipped); the ego vehicle moving 1 m per frame along the camera's z (forward) and turning 0.05 rad per frame.
struct TinySequence {
  static constexpr int kFrames = 4;
  static constexpr int kCarPoints = 125;        // 5^3
  static constexpr int kPedestrianPoints = 64;  // 4^3
  kitti::Calibration calib = kitti::defaultCalibration();
  std::vector<std::vector<Box>> boxes;  // per frame: car, pedestrian (LiDAR frame, track ids 1 and 2)
  std::vector<PointCloud> scans;
  std::vector<Eigen::Isometry3d> camera_poses;

  void write(const std::string& root, const std::string& seq, int frames, bool with_labels) {
    const std::filesystem::path training = std::filesystem::path(root) / "training";
    std::filesystem::create_directories(training / "velodyne" / seq);
    std::filesystem::create_directories(training / "calib");
    std::filesystem::create_directories(training / "pose");
    std::filesystem::create_directories(training / "label_02");
    kitti::writeCalibration((training / "calib" / (seq + ".txt")).string(), calib);
    std::vector<kitti::Label> labels;
    boxes.clear();
    scans.clear();
    camera_poses.clear();
    for (int f = 0; f < frames; ++f) {
      Box car{10.0 + 0.5 * f, 2.0, -0.9, 4.0, 1.8, 1.5, 0.3};  // x y z, l w h, yaw
      car.label = ObjectClass::Car;
      car.track_id = 1;
      Box ped{6.0, -3.0, -0.85, 0.8, 0.6, 1.7, -1.2};
      ped.label = ObjectClass::Pedestrian;
      ped.track_id = 2;
      const Box van{20.0, -6.0, -0.7, 5.0, 2.0, 2.0, 0.0};
      boxes.push_back({car, ped});

      PointCloud scan;
      for (double x = 2.0; x <= 30.0; x += 0.5) {
        for (double y = -10.0; y <= 10.0; y += 0.5) {
          scan.points.push_back({static_cast<float>(x), static_cast<float>(y), -1.73f, 0.2f});
        }
      }
      addLatticeInside(car, 5, 0.9f, scan);
      addLatticeInside(ped, 4, 0.5f, scan);
      addLatticeInside(van, 3, 0.7f, scan);
      char name[16];
      std::snprintf(name, sizeof(name), "%06d.bin", f);
      kitti::writeVelodyne((training / "velodyne" / seq / name).string(), scan);
      scans.push_back(scan);

      for (const Box& b : {car, ped}) {
        kitti::Label l = kitti::boxToLabel(b, calib);
        l.frame = f;
        labels.push_back(l);
      }
      kitti::Label van_label = kitti::boxToLabel(van, calib);
      van_label.type = "Van";
      van_label.frame = f;
      van_label.track_id = 2;
      labels.push_back(van_label);
      kitti::Label dont_care;
      dont_care.type = "DontCare";
      dont_care.frame = f;
      dont_care.track_id = -1;
      dont_care.bbox = {{100, 150, 200, 200}};
      dont_care.h = dont_care.w = dont_care.l = -1;
      dont_care.x = dont_care.y = dont_care.z = -1000;
      dont_care.rotation_y = -10;
      labels.push_back(dont_care);

      // Turning left while driving: the camera's y axis points down, so a left turn is a negative rotation about it.
      Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
      pose.linear() = Eigen::AngleAxisd(-0.05 * f, Eigen::Vector3d::UnitY()).toRotationMatrix();
      pose.translation() = Eigen::Vector3d(0.0, 0.0, 1.0 * f);  // camera z is forward
      camera_poses.push_back(pose);
    }
    if (with_labels) kitti::writeTrackingLabels((training / "label_02" / (seq + ".txt")).string(), labels);
    kitti::writePoses((training / "pose" / (seq + ".txt")).string(), camera_poses);
  }
};

}  // namespace test
}  // namespace ret3d
