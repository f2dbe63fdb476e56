// Detector outputs on disk, read into KITTI camera-frame labels (kitti::Label with a score).
// Three layouts are understood, so an evaluation or a relation stage can take detections from any of them:
//   - KITTI object result files: DIR/FFFFFF.txt (or DIR/data/FFFFFF.txt), one per frame, label_2 lines + score;
//   - KITTI tracking result files: DIR/SSSS.txt (or DIR/data/SSSS.txt), one per sequence, label_02 lines + score;
//   - per-class comma-separated files: DIR/<Class>/SSSS.txt, one line per box
//       frame,type,x1,y1,x2,y2,score,h,w,l,x,y,z,rot_y,alpha   (type 1 Pedestrian, 2 Car, 3 Cyclist)
//     as released with public detector outputs for the KITTI tracking benchmark (e.g. PointRCNN).
// A malformed line throws kitti::ParseError naming the file, the line and the field.
#pragma once

#include <map>
#include <string>
#include <vector>

#include "ret3d/io/kitti.h"

namespace ret3d {
namespace io {

enum class DetectionLayout { KittiObject, KittiTracking, PerClassCsv };

const char* layoutName(DetectionLayout layout);

// Reads one per-class comma-separated file. Labels get frame, type, bbox, score, h w l x y z rotation_y and alpha;
// truncated/occluded are 0 and track_id -1.
std::vector<kitti::Label> readPerClassCsvDetections(const std::string& path);

// Which layout a folder holds (looks at DIR and DIR/data); throws std::runtime_error when none matches.
DetectionLayout detectDetectionLayout(const std::string& dir);

// The folder that holds the files (DIR or DIR/data).
std::string detectionFilesDir(const std::string& dir);

// All detections of one tracking sequence, grouped by frame. For KittiTracking, DIR/SSSS.txt; for PerClassCsv,
// DIR/<Class>/SSSS.txt of every class folder present (Car, Pedestrian, Cyclist), merged. A missing file means no
// detections (an empty map), as a detector writes nothing for a sequence it found nothing in.
std::map<int, std::vector<kitti::Label>> readSequenceDetections(const std::string& dir, DetectionLayout layout,
                                                                const std::string& sequence);

// Detections of one object-layout frame ("000123"): DIR/000123.txt; empty when the file is missing.
std::vector<kitti::Label> readFrameDetections(const std::string& dir, const std::string& frame);

}  // namespace io
}  // namespace ret3d
