// This package's base detector run over the scans of KITTI tracking sequences, as the nodelet runs it online (the
// previous sweep moved by the ego poses): boxes with their features o_i, the inputs the relation modules learn from.
// Computed once and kept in a detection cache file (io/detection_cache.h) keyed by the model file and the data.
#pragma once

#include <string>
#include <vector>

#include "ret3d/detector/detector_options.h"
#include "ret3d/io/detection_cache.h"

namespace ret3d {
namespace train {

// `sequences` empty = every sequence with scans. `cache_path` empty = no cache.
io::SequenceDetections detectSequences(const std::string& data_dir, const std::vector<std::string>& sequences,
                                       const DetectorOptions& detector, const std::string& cache_path,
                                       bool progress = true);

}  // namespace train
}  // namespace ret3d
