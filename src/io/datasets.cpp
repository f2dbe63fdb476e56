// The KITTI tracking and object folder layouts: where each file of a sequence or frame lives.
#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <set>

#include "ret3d/io/kitti.h"

namespace fs = std::filesystem;

namespace ret3d {
namespace kitti {
namespace {

// The one sequence of a plain folder of scans.
const char* const kScanFolderSequence = "0000";

// ROOT/training when it exists, else ROOT itself (the training folder was given).
std::string resolveDir(const std::string& root) {
  std::error_code ec;
  if (!fs::is_directory(root, ec)) throw std::runtime_error("KITTI dataset folder '" + root + "' does not exist");
  const fs::path training = fs::path(root) / "training";
  return fs::is_directory(training, ec) ? training.string() : fs::path(root).string();
}

// Stems of the regular files in `dir` with extension `ext` (or of its subfolders when ext is empty).
std::set<std::string> stems(const fs::path& dir, const std::string& ext) {
  std::set<std::string> out;
  std::error_code ec;
  if (!fs::is_directory(dir, ec)) return out;
  for (const auto& e : fs::directory_iterator(dir, ec)) {
    const bool want = ext.empty() ? e.is_directory(ec) : (e.is_regular_file(ec) && e.path().extension() == ext);
    if (want) out.insert(e.path().stem().string());
  }
  return out;
}

bool isFile(const std::string& p) {
  std::error_code ec;
  return fs::is_regular_file(p, ec);
}

}  // namespace

TrackingDataset::TrackingDataset(const std::string& root) : dir_(resolveDir(root)) {
  std::error_code ec;
  scan_folder_ = !fs::is_directory(fs::path(dir_) / "velodyne", ec) && !stems(dir_, ".bin").empty();
}

std::vector<std::string> TrackingDataset::sequences() const {
  if (scan_folder_) return {kScanFolderSequence};
  // A sequence may have scans without labels (test split, simulator output) or labels without scans (box-level data).
  std::set<std::string> seqs = stems(fs::path(dir_) / "velodyne", "");
  for (const auto& s : stems(fs::path(dir_) / "label_02", ".txt")) seqs.insert(s);
  return {seqs.begin(), seqs.end()};
}

std::vector<int> TrackingDataset::frames(const std::string& seq) const {
  std::vector<int> out;
  if (scan_folder_ && seq != kScanFolderSequence) return out;
  for (const auto& s : stems(scan_folder_ ? fs::path(dir_) : fs::path(dir_) / "velodyne" / seq, ".bin")) {
    if (s.empty() || !std::all_of(s.begin(), s.end(), [](char c) { return c >= '0' && c <= '9'; })) continue;
    out.push_back(std::stoi(s));
  }
  std::sort(out.begin(), out.end());
  return out;
}

std::string TrackingDataset::velodynePath(const std::string& seq, int frame) const {
  char name[32];
  std::snprintf(name, sizeof(name), "%06d.bin", frame);
  if (scan_folder_) return (fs::path(dir_) / name).string();
  return (fs::path(dir_) / "velodyne" / seq / name).string();
}

std::string TrackingDataset::labelPath(const std::string& seq) const {
  return (fs::path(dir_) / "label_02" / (seq + ".txt")).string();
}
std::string TrackingDataset::calibPath(const std::string& seq) const {
  return (fs::path(dir_) / "calib" / (seq + ".txt")).string();
}
std::string TrackingDataset::posePath(const std::string& seq) const {
  return (fs::path(dir_) / "pose" / (seq + ".txt")).string();
}
std::string TrackingDataset::oxtsPath(const std::string& seq) const {
  return (fs::path(dir_) / "oxts" / (seq + ".txt")).string();
}
bool TrackingDataset::hasLabels(const std::string& seq) const { return isFile(labelPath(seq)); }

Calibration TrackingDataset::calibration(const std::string& seq) const {
  if (scan_folder_ && !isFile(calibPath(seq))) return defaultCalibration();
  return readCalibration(calibPath(seq));
}

std::vector<Eigen::Isometry3d> TrackingDataset::lidarPoses(const std::string& seq) const {
  // pose/ is the layout's primary ego-pose source (ARCHITECTURE.md); oxts/ is the fallback.
  if (isFile(posePath(seq))) return cameraPosesToLidar(readPoses(posePath(seq)), readCalibration(calibPath(seq)));
  if (isFile(oxtsPath(seq))) return oxtsToLidarPoses(readOxts(oxtsPath(seq)), readCalibration(calibPath(seq)));
  return {};
}

ObjectDataset::ObjectDataset(const std::string& root) : dir_(resolveDir(root)) {}

std::vector<std::string> ObjectDataset::frames() const {
  std::set<std::string> out = stems(fs::path(dir_) / "velodyne", ".bin");
  for (const auto& s : stems(fs::path(dir_) / "label_2", ".txt")) out.insert(s);
  return {out.begin(), out.end()};
}

std::string ObjectDataset::velodynePath(const std::string& frame) const {
  return (fs::path(dir_) / "velodyne" / (frame + ".bin")).string();
}
std::string ObjectDataset::labelPath(const std::string& frame) const {
  return (fs::path(dir_) / "label_2" / (frame + ".txt")).string();
}
std::string ObjectDataset::calibPath(const std::string& frame) const {
  return (fs::path(dir_) / "calib" / (frame + ".txt")).string();
}

Calibration ObjectDataset::calibration(const std::string& frame) const {
  if (!fs::is_directory(fs::path(dir_) / "calib")) return defaultCalibration();
  return readCalibration(calibPath(frame));
}

}  // namespace kitti
}  // namespace ret3d
