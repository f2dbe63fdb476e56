// KITTI object and tracking layouts: velodyne scans, labels, calibration, poses and OXTS; read and write.
// A malformed line throws ParseError "FILE:LINE: field 'NAME': problem" (wrong field count, a value that is not a
// finite number, a non-integer where KITTI has an integer); a problem with the whole file reads "FILE: problem".
// A file that cannot be opened or written throws std::runtime_error naming it (ParseError is a runtime_error too).
// Empty lines are skipped everywhere. Numbers are read and written independently of the C locale.
#pragma once

#include <array>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "ret3d/core/geometry.h"
#include "ret3d/core/types.h"

namespace ret3d {
namespace kitti {

class ParseError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// ---- velodyne scans: N x 4 float32 (x, y, z, reflectance in [0, 1]) ----
// A size that is not a multiple of 16 bytes is a ParseError naming the file. Points with a non-finite coordinate are
// dropped (with a warning); a NaN reflectance becomes 0; reflectance above 1 (a 0-255 file from another tool) is
// scaled by 1/255 (by 1/max when above 255, with a warning), then clamped to [0, 1].
PointCloud readVelodyne(const std::string& path);
void writeVelodyne(const std::string& path, const PointCloud& cloud);

// ---- labels ----
// One label line in KITTI camera coordinates. Object layout (label_2):
//   type truncated occluded alpha x1 y1 x2 y2 h w l x y z rotation_y [score]
// Tracking layout (label_02): frame track_id, then the same fields (truncated an integer level there).
// Writers use fixed notation with 6 decimals, which the KITTI devkits read; score is written only when present.
// The tracking writers throw std::invalid_argument for a label whose frame is negative (not set).
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
  std::array<Eigen::Matrix<double, 3, 4>, 4> P{{Eigen::Matrix<double, 3, 4>::Identity(),  // P0..P3 (P[2] == P2)
                                                Eigen::Matrix<double, 3, 4>::Identity(),
                                                Eigen::Matrix<double, 3, 4>::Identity(),
                                                Eigen::Matrix<double, 3, 4>::Identity()}};

  // R0_rect * Tr_velo_to_cam as a 4x4 affine matrix (LiDAR -> rectified camera). Used as given, not re-orthonormalised,
  // so veloToRect and rectToVelo (its general inverse) are exact inverses.
  Eigen::Matrix4d veloToRectMatrix() const;

  // Point in LiDAR frame -> rectified camera frame: R0_rect * Tr_velo_to_cam * p.
  Eigen::Vector3d veloToRect(const Eigen::Vector3d& p) const;
  Eigen::Vector3d rectToVelo(const Eigen::Vector3d& p) const;
  // Projection of a rectified-camera point into image 2 (pixels); nullopt when behind the camera.
  std::optional<Eigen::Vector2d> projectRect(const Eigen::Vector3d& p) const;
};
// Reads both key styles: object ("P2: ...", "R0_rect: ...", "Tr_velo_to_cam: ...") and tracking
// ("P2 ...", "R_rect ...", "Tr_velo_cam ...").
Calibration readCalibration(const std::string& path);
// P2, R0_rect (R_rect) and Tr_velo_to_cam (Tr_velo_cam) are required: a missing one is a ParseError naming the file
// and the key. Tr_imu_to_velo (Tr_imu_velo) is optional (identity); P0, P1, P3 are optional (zero when absent).
// Writes the object key style, which readCalibration reads back.
void writeCalibration(const std::string& path, const Calibration& calib);
// A KITTI-like calibration, used by the simulator: the real values of the tracking benchmark's sequences 0000-0013
// (one calibration, recorded 2011-09-26; identical to ../shared/data's calib/0001.txt).
Calibration defaultCalibration();

// KITTI's usual image size (pixels); images of some drives are a few pixels smaller.
inline const Eigen::Vector2d kImageSize(1242, 375);

// What lies behind the image-2 columns [u_min, u_max] (rows [v_min, v_max]) in the LiDAR frame's BEV: a wedge from
// camera 2's centre between the rays through the two side columns. The camera is slightly tilted, so each side's ray
// is taken at the top, middle and bottom rows and the widest kept. The whole image gives the labelled field of view;
// a DontCare box gives the region where unlabelled objects may stand.
BevWedge imageRegionWedge(const Calibration& calib, double u_min, double u_max, double v_min, double v_max,
                          double margin = 0);

// ---- label <-> box ----
// Track ids: KITTI tracking ids start at 0 (-1 = none, e.g. DontCare) while Box::track_id 0 means none, so
//   Box::track_id = kitti track_id + 1 when kitti track_id >= 0, else 0;   kitti track_id = Box::track_id - 1, or -1.
// Geometry: the box centre is rectToVelo(x, y - h/2, z) (camera y points down); length = l, width = w, height = h;
// yaw is the direction of the heading (cos ry, 0, -sin ry), rotated into the LiDAR frame, projected on the ground
// plane: atan2(dy, dx), wrapped to (-pi, pi]. boxToLabel inverts this exactly (label -> box -> label to ~1e-12).
//
// Camera label -> LiDAR-frame box. Type maps through classFromName (others, e.g. Van or DontCare, become Unknown:
// check the type first when that matters); score kept when present (else the Box default 1).
Box labelToBox(const Label& label, const Calibration& calib);
// LiDAR-frame box -> camera label. Fills h w l x y z rotation_y, alpha = wrapAngle(rotation_y - atan2(x, z)) (KITTI's
// observation angle; it matches the real labels), the 2D box (the projection of the 3D box's part at least 0.1 m in
// front of the camera, clipped to [0, width-1] x [0, height-1] when image_size is given; {0, 0, 0, 0} when nothing is
// in front), type from the class ("Misc" for Unknown), track id (mapping above), score. truncated/occluded are left 0,
// frame -1.
Label boxToLabel(const Box& box, const Calibration& calib,
                 const std::optional<Eigen::Vector2d>& image_size = Eigen::Vector2d(1242, 375));

// ---- poses ----
// pose/SSSS.txt: one row-major 3x4 camera-to-world matrix per line (KITTI odometry convention).
std::vector<Eigen::Isometry3d> readPoses(const std::string& path);
void writePoses(const std::string& path, const std::vector<Eigen::Isometry3d>& poses);
// Camera poses -> LiDAR poses in the first LiDAR frame: T_velo0_velo_t = Tr^-1 * T_cam0_cam0^-1 * T_cam0_cam_t * Tr,
// where Tr = R0_rect * Tr_velo_to_cam (nearest rigid transform): KITTI odometry poses are those of the *rectified* left
// camera (the odometry calib's Tr already includes R0_rect). Relative to the first pose, so the result starts at identity.
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
// then moved into the LiDAR frame with Tr_imu_to_velo: T_velo0_velo_t = Ti * T_imu0_imu_t * Ti^-1 (Ti = Tr_imu_to_velo).
// Rotation R = Rz(yaw) * Ry(pitch) * Rx(roll); yaw 0 points east.
std::vector<Eigen::Isometry3d> oxtsToLidarPoses(const std::vector<OxtsRecord>& records, const Calibration& calib);

// ---- dataset layouts ----
// Tracking layout: ROOT/training/{velodyne/SSSS/FFFFFF.bin, label_02/SSSS.txt, calib/SSSS.txt, pose/SSSS.txt,
// oxts/SSSS.txt}. ROOT may also be the training folder itself. The constructors throw std::runtime_error when ROOT is
// not a folder.
// A plain folder of consecutive scans (ROOT/FFFFFF.bin, no velodyne/ subfolder), as a recorder or converter leaves
// them, reads as one sequence "0000" without labels, calibration or poses.
class TrackingDataset {
 public:
  explicit TrackingDataset(const std::string& root);
  const std::string& dir() const { return dir_; }  // the folder holding velodyne/, label_02/, ...
  std::vector<std::string> sequences() const;      // "0000", ... sorted: velodyne/ subfolders and label_02/ files
  std::vector<int> frames(const std::string& seq) const;  // frame indices with a scan, sorted
  std::string velodynePath(const std::string& seq, int frame) const;
  std::string labelPath(const std::string& seq) const;
  std::string calibPath(const std::string& seq) const;
  std::string posePath(const std::string& seq) const;
  std::string oxtsPath(const std::string& seq) const;
  bool hasLabels(const std::string& seq) const;
  bool isScanFolder() const { return scan_folder_; }  // the plain folder of scans above
  // The sequence's calib/ file; for a scan folder without one, defaultCalibration() (its labels need a camera).
  Calibration calibration(const std::string& seq) const;
  // LiDAR poses T_velo0_velo_t from pose/ (preferred) or oxts/; empty when neither exists.
  std::vector<Eigen::Isometry3d> lidarPoses(const std::string& seq) const;

 private:
  std::string dir_;
  bool scan_folder_ = false;
};

// Object layout: ROOT/training/{velodyne,label_2,calib}/FFFFFF.{bin,txt}; ROOT may be the training folder itself.
class ObjectDataset {
 public:
  explicit ObjectDataset(const std::string& root);
  const std::string& dir() const { return dir_; }
  std::vector<std::string> frames() const;  // "000000", ... sorted: velodyne/*.bin and label_2/*.txt
  std::string velodynePath(const std::string& frame) const;
  std::string labelPath(const std::string& frame) const;
  std::string calibPath(const std::string& frame) const;
  // The frame's calib/ file; for a folder without calib/ at all (unlabelled scans), defaultCalibration(). A calib/
  // folder that lacks the frame's file is an error (readCalibration throws, naming the file).
  Calibration calibration(const std::string& frame) const;

 private:
  std::string dir_;
};

}  // namespace kitti
}  // namespace ret3d
