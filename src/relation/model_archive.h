// Model files of the learned stages: a torch archive holding a module's parameters and buffers plus one YAML metadata
// string (format name and version, classes, feature layout, the training config). Shared by the relation modules so
// every model file is written atomically and refused with the same kind of message when damaged.
#pragma once

#include <string>

#include <torch/torch.h>

namespace ret3d {
namespace relation {

// Writes `module` and `metadata_yaml` to `path` (via a temporary file and a rename: an interrupted save never leaves a
// truncated file under `path`); creates the parent folder.
void saveModelArchive(const std::string& path, const torch::nn::Module& module, const std::string& metadata_yaml);

// Opens `path` and returns its metadata string; `what` names the model kind in messages ("InterRM"). Throws
// std::runtime_error "<what> model <path>: ..." when the file is missing, truncated/corrupt, or has no metadata.
std::string readModelMetadata(const std::string& path, const std::string& what,
                              torch::serialize::InputArchive* archive);

// Loads the parameters and buffers of `module` from `archive`, checking every shape; throws std::runtime_error naming
// the first parameter that is missing or of another shape.
void loadModelParameters(torch::serialize::InputArchive& archive, torch::nn::Module& module, const std::string& path,
                         const std::string& what);

}  // namespace relation
}  // namespace ret3d
