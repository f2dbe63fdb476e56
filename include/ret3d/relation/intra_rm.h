// IntraRM, the intra-frame relation module of Ret3D (§3.2, eqs. (1)-(4)): the detections of one frame become the
// nodes of a sparse radius graph; m rounds of EdgeConv message passing with channel-wise max aggregation refine
// each node's features; a head predicts each box's refined centre, size and heading and its class scores.
//
// Inputs per object: the basic features d_i (centre, log size, heading as sin/cos, velocity, score, class one-hot)
// and, for a model trained with them, the detector's feature vector o_i. Both are normalised by the mean and
// standard deviation measured on the training data (stored in the model file; heading and one-hot are left as is).
//
// Outputs: the same detections, in the same order, with refined centre, size and yaw (residuals on the input box;
// the heading residual is at most pi/2, direction flips are left alone), the score replaced by the refined
// probability of the box's own class (calibrated: IntraRMArch::score_scale), and everything else (label, velocity,
// track id, point count, features) kept.
#pragma once

#include <cstdint>
#include <memory>
#include <string>

#include "ret3d/core/detections.h"
#include "ret3d/relation/intra_rm_config.h"

namespace ret3d {
namespace relation {

struct IntraRMImpl;  // the torch side: src/relation/intra_rm_network.h

struct IntraRMOptions {
  std::string model_path;  // a model file written by `ret3d train intra` (or IntraRM::save)
  int threads = 0;         // > 0: torch::set_num_threads(threads) when the module is created
  // Optional expectations checked against the model file (a mismatch is refused, saying what differs):
  double radius = -1;       // < 0: the radius the model was trained with
  int rounds = -1;          // < 0: any
  long feature_dim = -1;    // < 0: any
};

class IntraRM : public RelationModule<IntraRMImpl, IntraRMConfig> {
 public:
  // Loads options.model_path (errors: RelationModule's, or an expectation of `options` the file does not meet).
  explicit IntraRM(const IntraRMOptions& options);
  explicit IntraRM(const IntraRMArch& arch, std::uint64_t seed = 1) : RelationModule(arch, seed) {}

  // Refines one frame. Throws std::invalid_argument when the input's feature_dim differs from the model's (in
  // particular a model trained with detector features refuses featureless detections).
  Detections refine(const Detections& input) const;
};

// The 14 basic features d_i of a box, in network order (before normalisation):
// x, y, z, log l, log w, log h, sin yaw, cos yaw, vx, vy, score, one-hot Car, Pedestrian, Cyclist.
inline constexpr int kIntraBasicFeatures = 14;
void basicFeatures(const Box& box, float* out);

using IntraRMModelInfo = ModelInfo<IntraRMConfig>;
// Reads only the metadata of a model file (same checks as the constructor, without building the network).
IntraRMModelInfo readIntraRMModelInfo(const std::string& path);

}  // namespace relation
}  // namespace ret3d
