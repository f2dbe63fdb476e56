#include "ret3d/relation/inter_rm.h"

#include <stdexcept>

#include "inter_rm_network.h"

namespace ret3d {
namespace relation {

InterRM::InterRM(const InterRMOptions& options) : RelationModule(options.model_path) {
  const InterRMArch& a = arch();
  const std::string where = "InterRM model " + options.model_path + ": ";
  if (options.c_enc >= 0 && options.c_enc != a.c_enc)
    throw std::runtime_error(where + "has C_enc " + std::to_string(a.c_enc) + ", the options ask for " +
                             std::to_string(options.c_enc));
  if (!options.positional_encoding.empty() &&
      options.positional_encoding != positionalEncodingName(a.positional_encoding))
    throw std::runtime_error(where + "was trained with the " + positionalEncodingName(a.positional_encoding) +
                             " positional encoding, the options ask for " + options.positional_encoding);
  setTorchThreads(options.threads);
}

std::vector<Box> InterRM::refine(const std::vector<InterRMSequence>& sequences) const {
  if (sequences.empty()) return {};
  std::vector<const InterRMSequence*> ptrs;
  ptrs.reserve(sequences.size());
  for (const auto& s : sequences) ptrs.push_back(&s);
  torch::InferenceMode guard;
  const InterRMInputs in = makeInterRMInputs(ptrs, arch().max_history);
  return applyInterRMOutput(ptrs, impl_->net->forward(in), arch().regress_size);
}

}  // namespace relation
}  // namespace ret3d
