#include "ret3d/io/detections.h"

#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <limits>
#include <sstream>

#include "ret3d/core/enum_names.h"

namespace ret3d {
namespace io {

namespace fs = std::filesystem;

namespace {

const char* const kCsvFields[] = {"frame", "type", "x1",    "y1", "x2", "y2", "score", "h",
                                  "w",     "l",    "x",     "y",  "z",  "rot_y", "alpha"};
constexpr int kCsvFieldCount = 15;
const char* const kCsvClassFolders[] = {"Car", "Pedestrian", "Cyclist"};

[[noreturn]] void fail(const std::string& path, int line, const std::string& what) {
  std::ostringstream oss;
  oss << path << ":" << line << ": " << what;
  throw kitti::ParseError(oss.str());
}

double parseNumber(const std::string& text, const std::string& path, int line, const char* field) {
  const char* begin = text.c_str();
  char* end = nullptr;
  errno = 0;
  const double v = std::strtod(begin, &end);
  while (end && (*end == ' ' || *end == '\t' || *end == '\r')) ++end;
  if (text.empty() || end == begin || *end != '\0' || errno == ERANGE) {
    fail(path, line, std::string("field '") + field + "': not a number: '" + text + "'");
  }
  return v;
}

bool allDigits(const std::string& s, std::size_t n) {
  if (s.size() != n) return false;
  for (char c : s) {
    if (c < '0' || c > '9') return false;
  }
  return true;
}

// Counts *.txt files in `dir` whose stem has `digits` digits.
int countNumbered(const fs::path& dir, std::size_t digits) {
  int n = 0;
  std::error_code ec;
  for (fs::directory_iterator it(dir, ec), end; !ec && it != end; it.increment(ec)) {
    if (it->is_regular_file() && it->path().extension() == ".txt" && allDigits(it->path().stem().string(), digits)) {
      ++n;
    }
  }
  return n;
}

}  // namespace

const char* layoutName(DetectionLayout layout) {
  static constexpr std::array<const char*, 3> kNames = {"KITTI object result files (FFFFFF.txt)",
                                                        "KITTI tracking result files (SSSS.txt)",
                                                        "per-class comma-separated files (<Class>/SSSS.txt)"};
  static_assert(static_cast<std::size_t>(DetectionLayout::PerClassCsv) + 1 == kNames.size());
  return enumName(layout, kNames);
}

std::vector<kitti::Label> readPerClassCsvDetections(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw kitti::ParseError(path + ": cannot open");
  std::vector<kitti::Label> out;
  std::string line;
  int line_no = 0;
  while (std::getline(in, line)) {
    ++line_no;
    if (line.find_first_not_of(" \t\r") == std::string::npos) continue;
    std::vector<std::string> fields;
    std::stringstream ss(line);
    std::string f;
    while (std::getline(ss, f, ',')) fields.push_back(f);
    if (static_cast<int>(fields.size()) != kCsvFieldCount) {
      fail(path, line_no, "expected " + std::to_string(kCsvFieldCount) + " comma-separated fields (" +
                              "frame,type,x1,y1,x2,y2,score,h,w,l,x,y,z,rot_y,alpha), got " +
                              std::to_string(fields.size()));
    }
    double v[kCsvFieldCount];
    for (int i = 0; i < kCsvFieldCount; ++i) v[i] = parseNumber(fields[i], path, line_no, kCsvFields[i]);
    kitti::Label l;
    // Range-checked before the casts: a double beyond int's range does not convert (undefined behaviour).
    if (!(v[0] >= 0 && v[0] <= std::numeric_limits<int>::max()) || v[0] != std::floor(v[0]))
      fail(path, line_no, "field 'frame': not a frame index");
    l.frame = static_cast<int>(v[0]);
    switch (v[1] == 1 || v[1] == 2 || v[1] == 3 ? static_cast<int>(v[1]) : 0) {
      case 1:
        l.type = "Pedestrian";
        break;
      case 2:
        l.type = "Car";
        break;
      case 3:
        l.type = "Cyclist";
        break;
      default:
        fail(path, line_no, "field 'type': expected 1 (Pedestrian), 2 (Car) or 3 (Cyclist), got " + fields[1]);
    }
    l.bbox = {v[2], v[3], v[4], v[5]};
    l.score = v[6];
    l.h = v[7];
    l.w = v[8];
    l.l = v[9];
    l.x = v[10];
    l.y = v[11];
    l.z = v[12];
    l.rotation_y = v[13];
    l.alpha = v[14];
    out.push_back(std::move(l));
  }
  return out;
}

std::string detectionFilesDir(const std::string& dir) {
  const fs::path data = fs::path(dir) / "data";
  if (fs::is_directory(data) && (countNumbered(data, 6) > 0 || countNumbered(data, 4) > 0)) return data.string();
  return dir;
}

DetectionLayout detectDetectionLayout(const std::string& dir) {
  if (!fs::is_directory(dir)) throw std::runtime_error(dir + ": not a folder of detections");
  for (const char* cls : kCsvClassFolders) {
    if (fs::is_directory(fs::path(dir) / cls) && countNumbered(fs::path(dir) / cls, 4) > 0) {
      return DetectionLayout::PerClassCsv;
    }
  }
  const fs::path files = detectionFilesDir(dir);
  const int objects = countNumbered(files, 6), sequences = countNumbered(files, 4);
  if (objects > 0 && objects >= sequences) return DetectionLayout::KittiObject;
  if (sequences > 0) return DetectionLayout::KittiTracking;
  throw std::runtime_error(dir + ": no detection files found (expected FFFFFF.txt, SSSS.txt or <Class>/SSSS.txt, "
                                 "directly or under data/)");
}

std::map<int, std::vector<kitti::Label>> readSequenceDetections(const std::string& dir, DetectionLayout layout,
                                                                const std::string& sequence) {
  std::map<int, std::vector<kitti::Label>> by_frame;
  std::vector<kitti::Label> all;
  if (layout == DetectionLayout::PerClassCsv) {
    for (const char* cls : kCsvClassFolders) {
      const fs::path p = fs::path(dir) / cls / (sequence + ".txt");
      if (!fs::exists(p)) continue;
      auto labels = readPerClassCsvDetections(p.string());
      all.insert(all.end(), std::make_move_iterator(labels.begin()), std::make_move_iterator(labels.end()));
    }
  } else if (layout == DetectionLayout::KittiTracking) {
    const fs::path p = fs::path(detectionFilesDir(dir)) / (sequence + ".txt");
    if (fs::exists(p)) all = kitti::readTrackingLabels(p.string());
  } else {
    throw std::runtime_error(dir + ": holds per-frame object results; sequences need tracking or per-class files");
  }
  for (auto& l : all) by_frame[l.frame].push_back(std::move(l));
  return by_frame;
}

std::vector<kitti::Label> readFrameDetections(const std::string& dir, const std::string& frame) {
  const fs::path p = fs::path(detectionFilesDir(dir)) / (frame + ".txt");
  if (!fs::exists(p)) return {};
  return kitti::readObjectLabels(p.string());
}

}  // namespace io
}  // namespace ret3d
