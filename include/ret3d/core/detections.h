// One frame's detections as they travel between stages (detector -> IntraRM -> tracker -> InterRM): the boxes and,
// when the producer has them, one feature vector per box (the detector's BEV feature at the box centre). An external
// detector's boxes come with feature_dim 0. Mirrors msg/DetectionArray.msg.
#pragma once

#include <cstddef>
#include <stdexcept>
#include <string>
#include <vector>

#include "ret3d/core/types.h"

namespace ret3d {

struct Detections {
  std::vector<Box> boxes;
  std::size_t feature_dim = 0;  // 0 = no features
  std::vector<float> features;  // row-major, boxes.size() x feature_dim

  std::size_t size() const { return boxes.size(); }
  bool empty() const { return boxes.empty(); }
  bool hasFeatures() const { return feature_dim > 0; }
  // Row i of the feature matrix (feature_dim floats).
  const float* feature(std::size_t i) const { return features.data() + i * feature_dim; }
  float* feature(std::size_t i) { return features.data() + i * feature_dim; }
  // Throws std::invalid_argument when the feature matrix does not have boxes.size() x feature_dim entries.
  void validate() const {
    if (features.size() != boxes.size() * feature_dim) {
      throw std::invalid_argument("Detections: " + std::to_string(features.size()) + " feature values for " +
                                  std::to_string(boxes.size()) + " boxes of feature_dim " +
                                  std::to_string(feature_dim) + " (expected " +
                                  std::to_string(boxes.size() * feature_dim) + ")");
    }
  }
};

}  // namespace ret3d
