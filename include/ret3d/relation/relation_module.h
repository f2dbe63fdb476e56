// What IntraRM and InterRM share in their interface: a configuration of a `model:` and a `train:` section, the
// metadata of a model file, and the class over the torch implementation (its members are written once, in
// src/relation/model_archive.h, and instantiated for each module). Free of torch, like the modules' headers.
#pragma once

#include <cstdint>
#include <memory>
#include <string>

namespace ret3d {
namespace relation {

// Arch: what defines a trained network (saved in every model file); Train: the training settings.
template <class Arch, class Train>
struct RelationConfig {
  Arch model;
  Train train;
};

// The configuration as YAML text, which the module's parse function reads back.
template <class Arch, class Train>
std::string toYaml(const RelationConfig<Arch, Train>& config);

// A model file's metadata (also its YAML header, readable with `ret3d train intra|inter --inspect`).
template <class Config>
struct ModelInfo {
  int format_version = 0;
  Config config;           // the configuration the model was trained with (config.model = its shape)
  std::string trained_on;  // free text: data and command
};

// Impl (src/relation) holds the metadata `info` and the network `net`.
template <class ImplT, class ConfigT>
class RelationModule {
 public:
  using Impl = ImplT;
  using Config = ConfigT;
  using Arch = decltype(Config::model);

  const Arch& arch() const;
  const ModelInfo<Config>& info() const;
  // Writes the model file (parameters, normalisation, metadata).
  void save(const std::string& path) const;

  // For the training code: the implementation, torch types included.
  Impl& impl() { return *impl_; }
  const Impl& impl() const { return *impl_; }

 protected:
  // Loads a model file; throws std::runtime_error saying what is wrong with it (missing, truncated, not a model of
  // this module, another format version or feature layout, other classes, parameters that don't fit the metadata).
  explicit RelationModule(const std::string& model_path);
  // An untrained module of the given shape (random weights from `seed`; refinement starts as the identity).
  RelationModule(const Arch& arch, std::uint64_t seed);
  ~RelationModule();
  RelationModule(RelationModule&&) noexcept;
  RelationModule& operator=(RelationModule&&) noexcept;

  std::unique_ptr<Impl> impl_;
};

// Sets the number of CPU threads libtorch uses, process-wide (the learned stages share them); <= 0: unchanged.
void setTorchThreads(int threads);

}  // namespace relation
}  // namespace ret3d
