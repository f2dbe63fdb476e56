#include "ret3d/relation/inter_rm.h"

#include <stdexcept>

#include "inter_rm_network.h"

namespace ret3d {
namespace relation {

InterRM::InterRM(const InterRMOptions& options) : impl_(std::make_unique<Impl>()) {
  if (options.model_path.empty()) throw std::runtime_error("InterRM: no model file given (model_path is empty)");
  loadInterRMModel(options.model_path, impl_.get());
  const InterRMArch& a = impl_->info.config.model;
  const std::string where = "InterRM model " + options.model_path + ": ";
  if (options.c_enc >= 0 && options.c_enc != a.c_enc)
    throw std::runtime_error(where + "has C_enc " + std::to_string(a.c_enc) + ", the options ask for " +
                             std::to_string(options.c_enc));
  if (!options.positional_encoding.empty() &&
      options.positional_encoding != positionalEncodingName(a.positional_encoding))
    throw std::runtime_error(where + "was trained with the " + positionalEncodingName(a.positional_encoding) +
                             " positional encoding, the options ask for " + options.positional_encoding);
  if (options.threads > 0) torch::set_num_threads(options.threads);
}

InterRM::InterRM(const InterRMArch& arch, std::uint64_t seed) : impl_(std::make_unique<Impl>()) {
  torch::manual_seed(seed);
  impl_->info.format_version = kInterRMFormatVersion;
  impl_->info.config.model = arch;
  impl_->net = InterRMNet(arch);
  impl_->net->eval();
}

InterRM::~InterRM() = default;
InterRM::InterRM(InterRM&&) noexcept = default;
InterRM& InterRM::operator=(InterRM&&) noexcept = default;

const InterRMArch& InterRM::arch() const { return impl_->info.config.model; }
const InterRMModelInfo& InterRM::info() const { return impl_->info; }
void InterRM::save(const std::string& path) const { saveInterRMModel(path, *impl_); }

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
