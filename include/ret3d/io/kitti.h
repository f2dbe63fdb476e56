// KITTI object and tracking layouts: velodyne scans, labels, calibration, poses and OXTS; read and write.
// A malformed line throws ParseError naming the file, the line number and the field.
#pragma once

#include <array>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "ret3d/core/types.h"

namespace ret3d {
namespace kitti {

class ParseError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// ---- velodyne scans: N x 4 float32 (x, y, z, reflectance in [0, 1]) ----
PointCloud readVelodyne(const std::string& path);
void writeVelodyne(const std::string& path, const PointCloud& cloud);

// ---- labels ----
// One label line in KITTI camera coordinates. Object layout (label_2):
//   type truncated occluded alpha x1 y1 x2 y2 h w l x y z rotation_y [score]
// Tracking layout (label_02): frame track_id, then the same fields.
struct Label {
  int frame = -1;            // tracking layout only
  int track_id = -1;         // tracking layout only (-1 for DontCare)
  std::string type;          // Car, Van, Truck, Pedestrian, Person_sitting, Cyclist, Tram, Misc, DontCare
  double truncated = 0;      // 0..1 (tracking uses 0, 1, 2)
  int occluded = 0;          // 0..3
  double alpha = -10;        // observation angle, [-pi, pi]
  std::array<double, 4> bbox{{0, 0, 0, 0}};  // 2D box in image 2: x1 y1 x2 y2 (pixels)
  double h = 0, w = 0, l = 0;                // height, width, length (m)
  double x = 0, y = 0, z = 0;                // bottom centre in rectified camera coordinates (m)
  double rotation_y = 0;                     // about camera y, [-pi, pi]
  std::optional<double> score;               // present in result files
};

std::vector<Label> readObjectLabels(const std::string& path);    // label_2 / object result files
std::vector<Label> readTrackingLabels(const std::string& path);  // label_02 / tracking result files
void writeObjectLabels(const std::string& path, const std::vector<Label>& labels);
void writeTrackingLabels(const std::string& path, const std::vector<Label>& labels);
std::string formatObjectLabel(const Label& l);
std::string formatTrackingLabel(const Label& l);

// ---- calibration ----
struct Calibration {
  Eigen::Matrix<double, 3, 4> P2 = Eigen::Matrix<double, 3, 4>::Identity();
  Eigen::Matrix3d R0_rect = Eigen::Matrix3d::Identity();
  Eigen::Isometry3d velo_to_cam = Eigen::Isometry3d::Identity();  // Tr_velo_to_cam
  Eigen::Isometry3d imu_to_velo = Eigen::Isometry3d::Identity();  // Tr_imu_to_velo (identity when absent)
  std::array<Eigen::Matrix<double, 3, 4>, 4> P{};                  // P0..P3 (P[2] == P2)

  // Point in LiDAR frame -> rectified camera frame: R0_rect * Tr_velo_to_cam * p.
  Eigen::Vector3d veloToRect(const Eigen::Vector3d& p) const;
  Eigen::Vector3d rectToVelo(const Eigen::Vector3d& p) const;
  // Projection of a rectified-camera point into image 2 (pixels); nullopt when behind the camera.
  std::optional<Eigen::Vector2d> projectRect(const Eigen::Vector3d& p) const;
};
// Reads both key styles: object ("P2: ...", "R0_rect: ...", "Tr_velo_to_cam: ...") and tracking
// ("P2 ...", "R_rect ...", "Tr_velo_cam ...").
Calibration readCalibration(const std::string& path);
// Writes the object key style, which readCalibration reads back.
void writeCalibration(const std::string& path, const Calibration& calib);
// A KITTI-like calibration (the values of the tracking benchmark's sequence 0000), used by the simulator.
Calibration defaultCalibration();

// ---- label <-> box ----
// Camera label (bottom centre, rotation_y) -> LiDAR-frame box (geometric centre, yaw). Type maps through
// classFromName (others become Unknown); track id kept when >= 0; score kept when present.
Box labelToBox(const Label& label, const Calibration& calib);
// LiDAR-frame box -> camera label. Fills h w l x y z rotation_y, alpha, the 2D box (projected 3D corners, clipped to
// the image when image_size is given), type from the class, track id and score. truncated/occluded are left 0.
Label boxToLabel(const Box& box, const Calibration& calib,
                 const std::optional<Eigen::Vector2d>& image_size = Eigen::Vector2d(1242, 375));

// ---- poses ----
// pose/SSSS.txt: one row-major 3x4 camera-to-world matrix per line (KITTI odometry convention).
std::vector<Eigen::Isometry3d> readPoses(const std::string& path);
void writePoses(const std::string& path, const std::vector<Eigen::Isometry3d>& poses);
// Camera poses -> LiDAR poses in the first LiDAR frame: T_velo0_velo_t = Tr^-1 * T_cam0_cam_t * Tr.
std::vector<Eigen::Isometry3d> cameraPosesToLidar(const std::vector<Eigen::Isometry3d>& cam_poses,
                                                  const Calibration& calib);

// ---- OXTS ----
struct OxtsRecord {
  std::array<double, 30> values{};  // lat lon alt roll pitch yaw vn ve vf vl vu ax ay az af al au wx wy wz wf wl wu
                                    // pos_accuracy vel_accuracy navstat numsats posmode velmode orimode
  double lat() const { return values[0]; }
  double lon() const { return values[1]; }
  double alt() const { return values[2]; }
  double roll() const { return values[3]; }
  double pitch() const { return values[4]; }
  double yaw() const { return values[5]; }
};
std::vector<OxtsRecord> readOxts(const std::string& path);
void writeOxts(const std::string& path, const std::vector<OxtsRecord>& records);
// IMU poses relative to the first record (Mercator projection with the first latitude's scale, as the KITTI devkit),
// then moved into the LiDAR frame with Tr_imu_to_velo: T_velo0_velo_t.
std::vector<Eigen::Isometry3d> oxtsToLidarPoses(const std::vector<OxtsRecord>& records, const Calibration& calib);

// ---- dataset layouts ----
// Tracking layout: ROOT/training/{velodyne/SSSS/FFFFFF.bin, label_02/SSSS.txt, calib/SSSS.txt, pose/SSSS.txt,
// oxts/SSSS.txt}. ROOT may also be the training folder itself.
class TrackingDataset {
 public:
  explicit TrackingDataset(const std::string& root);
  const std::string& dir() const { return dir_; }  // the folder holding velodyne/, label_02/, ...
  std::vector<std::string> sequences() const;      // "0000", ... sorted, from velodyne/ or label_02/
  std::vector<int> frames(const std::string& seq) const;  // frame indices with a scan, sorted
  std::string velodynePath(const std::string& seq, int frame) const;
  std::string labelPath(const std::string& seq) const;
  std::string calibPath(const std::string& seq) const;
  std::string posePath(const std::string& seq) const;
  std::string oxtsPath(const std::string& seq) const;
  bool hasLabels(const std::string& seq) const;
  // LiDAR poses T_velo0_velo_t from pose/ (preferred) or oxts/; empty when neither exists.
  std::vector<Eigen::Isometry3d> lidarPoses(const std::string& seq) const;

 private:
  std::string dir_;
};

// Object layout: ROOT/training/{velodyne,label_2,calib}/FFFFFF.{bin,txt}; ROOT may be the training folder itself.
class ObjectDataset {
 public:
  explicit ObjectDataset(const std::string& root);
  const std::string& dir() const { return dir_; }
  std::vector<std::string> frames() const;  // "000000", ... sorted, from velodyne/ or label_2/
  std::string velodynePath(const std::string& frame) const;
  std::string labelPath(const std::string& frame) const;
  std::string calibPath(const std::string& frame) const;

 private:
  std::string dir_;
};

}  // namespace kitti
}  // namespace ret3d
