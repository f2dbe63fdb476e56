#include "ret3d/relation/intra_rm.h"

#include <cmath>
#include <stdexcept>

#include "intra_rm_network.h"

namespace ret3d {
namespace relation {

IntraRM::IntraRM(const IntraRMOptions& options) : RelationModule(options.model_path) {
  const IntraRMArch& a = arch();
  const std::string where = "IntraRM model " + options.model_path + ": ";
  if (options.radius >= 0 && std::abs(options.radius - a.radius) > 1e-9)
    throw std::runtime_error(where + "trained with radius " + std::to_string(a.radius) + " m, the options ask for " +
                             std::to_string(options.radius) + " m");
  if (options.rounds >= 0 && options.rounds != a.rounds)
    throw std::runtime_error(where + "has " + std::to_string(a.rounds) + " rounds, the options ask for " +
                             std::to_string(options.rounds));
  if (options.feature_dim >= 0 && static_cast<std::size_t>(options.feature_dim) != a.feature_dim)
    throw std::runtime_error(where + "takes detector features of length " + std::to_string(a.feature_dim) +
                             ", the options ask for " + std::to_string(options.feature_dim));
  setTorchThreads(options.threads);
}

Detections IntraRM::refine(const Detections& input) const {
  input.validate();
  const IntraRMArch& a = arch();
  if (a.feature_dim > 0 && input.feature_dim != a.feature_dim) {
    if (input.feature_dim == 0)
      throw std::invalid_argument(
          "IntraRM: this model was trained with detector features (feature_dim " + std::to_string(a.feature_dim) +
          ") but the detections carry none; run it behind the detector it was trained with, or use a model "
          "trained without features (feature_dim 0, e.g. models/kitti_pointrcnn/intra_rm.pt)");
    throw std::invalid_argument("IntraRM: this model takes detector features of length " +
                                std::to_string(a.feature_dim) + ", the detections carry " +
                                std::to_string(input.feature_dim));
  }
  for (std::size_t i = 0; i < input.size(); ++i) {
    const Box& b = input.boxes[i];
    if (!std::isfinite(b.x) || !std::isfinite(b.y) || !std::isfinite(b.z) || !std::isfinite(b.yaw) ||
        !std::isfinite(b.length) || !std::isfinite(b.width) || !std::isfinite(b.height) || !std::isfinite(b.score))
      throw std::invalid_argument("IntraRM: detection " + std::to_string(i) + " has a non-finite field");
  }
  if (input.empty()) return input;

  // A featureless model ignores features the input may carry: it refines any detector's boxes.
  Detections stripped;
  const Detections* src = &input;
  if (a.feature_dim == 0 && input.feature_dim > 0) {
    stripped.boxes = input.boxes;
    src = &stripped;
  }
  torch::InferenceMode guard;
  const IntraRMInputs in = makeIntraRMInputs({src}, a);
  const IntraRMOutput out = impl_->net->forward(in.basic, in.feat, in.source, in.target);
  return applyIntraRMOutput(input, out, a);
}

}  // namespace relation
}  // namespace ret3d
