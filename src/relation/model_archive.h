// Model files of the relation modules (IntraRM, InterRM): a torch archive holding a module's parameters and buffers
// plus one YAML metadata string (format name and version, classes, feature layout, the training config). One writer
// and one reader for both, so every model file is written atomically and refused with the same kind of message when
// damaged; and the members of RelationModule (ret3d/relation/relation_module.h), which each module's .cpp
// instantiates for its Impl (a ModuleState with a static ModelFormat kFormat and a static parseConfig).
#pragma once

#include <stdexcept>
#include <string>

#include <torch/torch.h>

#include "ret3d/relation/relation_module.h"

namespace ret3d {
namespace relation {

// How the parameters are stored: IntraRM's files hold torch::nn::Module::save's nested archives, InterRM's one flat
// entry per parameter. Each module keeps its layout, so the model files already written load as they are.
enum class ArchiveLayout { Nested, Flat };

struct ModelFormat {
  std::string what;    // "IntraRM": names the model kind in messages
  std::string name;    // the metadata's `format`, e.g. "ret3d-intra-rm"
  int version;         // the metadata's `format_version`: the one this build reads and writes
  int basic_features;  // the input layout the network is built for (the metadata's `basic_features`)
  ArchiveLayout layout;
};

// Writes `module` and `metadata_yaml` to `path` (via a temporary file and a rename: an interrupted save never leaves a
// truncated file under `path`); creates the parent folder.
void saveModelArchive(const std::string& path, const torch::nn::Module& module, const std::string& metadata_yaml,
                      ArchiveLayout layout = ArchiveLayout::Flat);

// Opens `path` and returns its metadata string; `what` names the model kind in messages ("InterRM"). Throws
// std::runtime_error "<what> model <path>: ..." when the file is missing, truncated/corrupt, or has no metadata.
std::string readModelMetadata(const std::string& path, const std::string& what,
                              torch::serialize::InputArchive* archive);

// Loads the parameters and buffers of `module` from `archive`, checking every shape; throws std::runtime_error naming
// the first parameter that is missing or of another shape.
void loadModelParameters(torch::serialize::InputArchive& archive, torch::nn::Module& module, const std::string& path,
                         const std::string& what, ArchiveLayout layout = ArchiveLayout::Flat);

// The metadata of a model of `format`, with the training configuration as YAML text.
std::string modelMetadataYaml(const ModelFormat& format, const std::string& trained_on, const std::string& config_yaml);

// The metadata read from a model file and checked against `format` (format name and version, classes, feature layout).
struct ModelMetadata {
  int format_version = 0;
  std::string trained_on, config_yaml;
};
ModelMetadata readCheckedMetadata(const std::string& path, const ModelFormat& format,
                                  torch::serialize::InputArchive* archive);

// The model file's metadata, its configuration read by parse_config(yaml, source) (the module's parse function).
template <class Info, class ParseConfig>
Info readModelInfo(const std::string& path, const ModelFormat& format, ParseConfig parse_config,
                   torch::serialize::InputArchive* archive) {
  const ModelMetadata m = readCheckedMetadata(path, format, archive);
  Info info;
  info.format_version = m.format_version;
  info.trained_on = m.trained_on;
  try {
    info.config = parse_config(m.config_yaml, path + " (metadata)");
  } catch (const std::exception& e) {
    throw std::runtime_error(format.what + " model " + path + ": " + e.what());
  }
  return info;
}

// What a RelationModule's Impl holds besides its format (kFormat) and parse function (parseConfig).
template <class NetT, class Config>
struct ModuleState {
  using Net = NetT;
  ModelInfo<Config> info;
  Net net{nullptr};
};

// ---- RelationModule's members and loading ---------------------------------------------------------------------------

// Reads the model file at `path` into `impl` (metadata and network, in eval mode).
template <class Impl>
void loadModule(const std::string& path, Impl* impl) {
  const ModelFormat& format = Impl::kFormat;
  if (path.empty()) throw std::runtime_error(format.what + ": no model file given (model_path is empty)");
  torch::serialize::InputArchive archive;
  auto info = readModelInfo<decltype(impl->info)>(path, format, Impl::parseConfig, &archive);
  typename Impl::Net net(info.config.model);
  loadModelParameters(archive, *net, path, format.what, format.layout);
  net->eval();
  impl->info = std::move(info);
  impl->net = net;
}

template <class Impl, class Config>
RelationModule<Impl, Config>::RelationModule(const std::string& model_path) : impl_(std::make_unique<Impl>()) {
  loadModule(model_path, impl_.get());
}

template <class Impl, class Config>
RelationModule<Impl, Config>::RelationModule(const Arch& arch, std::uint64_t seed) : impl_(std::make_unique<Impl>()) {
  torch::manual_seed(seed);
  impl_->info.format_version = Impl::kFormat.version;
  impl_->info.config.model = arch;
  impl_->net = typename Impl::Net(arch);
  impl_->net->eval();
}

template <class Impl, class Config>
RelationModule<Impl, Config>::~RelationModule() = default;
template <class Impl, class Config>
RelationModule<Impl, Config>::RelationModule(RelationModule&&) noexcept = default;
template <class Impl, class Config>
RelationModule<Impl, Config>& RelationModule<Impl, Config>::operator=(RelationModule&&) noexcept = default;

template <class Impl, class Config>
const typename RelationModule<Impl, Config>::Arch& RelationModule<Impl, Config>::arch() const {
  return impl_->info.config.model;
}

template <class Impl, class Config>
const ModelInfo<Config>& RelationModule<Impl, Config>::info() const {
  return impl_->info;
}

template <class Impl, class Config>
void RelationModule<Impl, Config>::save(const std::string& path) const {
  const ModelFormat& format = Impl::kFormat;
  saveModelArchive(path, *impl_->net, modelMetadataYaml(format, impl_->info.trained_on, toYaml(impl_->info.config)),
                   format.layout);
}

// readIntraRMModelInfo, readInterRMModelInfo.
template <class Impl>
auto readModuleInfo(const std::string& path) {
  torch::serialize::InputArchive archive;
  return readModelInfo<decltype(Impl::info)>(path, Impl::kFormat, Impl::parseConfig, &archive);
}

}  // namespace relation
}  // namespace ret3d
