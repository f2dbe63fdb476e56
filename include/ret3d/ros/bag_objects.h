// Reading ret3d/Object3DArray messages (ground truth or pipeline output) back from a bag, for offline evaluation.
#pragma once

#include <string>
#include <vector>

#include "ret3d/core/types.h"

namespace ret3d {

// One message: its header stamp (seconds), frame id and boxes.
struct StampedObjects {
  double stamp = 0;
  std::string frame_id;
  std::vector<Box> boxes;
};

// Every Object3DArray message on `topic`, in bag order. Throws std::runtime_error when the bag cannot be opened, or
// when the topic is absent or of another type (the message lists the bag's topics and their types).
std::vector<StampedObjects> readBagObjects(const std::string& bag_path, const std::string& topic);

}  // namespace ret3d
