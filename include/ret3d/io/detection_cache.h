// A detector's outputs on whole sequences (boxes with their features o_i) in one binary file, so they are computed
// once and reused by the trainings and ablations of the relation modules. Layout:
//   "RET3DDET" | uint32 version | string key | uint64 entries | per entry: string sequence | int32 frame |
//   uint64 boxes | uint64 feature_dim | boxes (fixed fields) | features (float32, boxes x feature_dim)
// Strings are uint64 length + bytes. The key names what produced the file (e.g. the model and data), so a stale
// cache is recomputed rather than used.
#pragma once

#include <map>
#include <string>

#include "ret3d/core/detections.h"

namespace ret3d {
namespace io {

using SequenceDetections = std::map<std::string, std::map<int, Detections>>;  // sequence -> frame -> detections

void writeDetectionCache(const std::string& path, const std::string& key, const SequenceDetections& detections);
// False when the file does not exist or was written for another key; throws std::runtime_error naming the file when
// it is truncated or not a detection cache.
bool readDetectionCache(const std::string& path, const std::string& key, SequenceDetections* detections);

}  // namespace io
}  // namespace ret3d
