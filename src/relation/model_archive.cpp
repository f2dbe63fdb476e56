#include "model_archive.h"

#include <filesystem>
#include <stdexcept>
#include <vector>

#include <yaml-cpp/yaml.h>

#include "ret3d/core/types.h"

namespace ret3d {
namespace relation {

namespace {

constexpr const char* kMetaKey = "ret3d_metadata";

[[noreturn]] void bad(const std::string& what, const std::string& path, const std::string& msg) {
  throw std::runtime_error(what + " model " + path + ": " + msg);
}

std::string firstLine(const std::exception& e) {
  std::string m = e.what();
  return m.substr(0, m.find('\n'));
}

std::string shapeString(const torch::IntArrayRef& s) {
  std::string out = "[";
  for (std::size_t i = 0; i < s.size(); ++i) out += (i ? ", " : "") + std::to_string(s[i]);
  return out + "]";
}

std::string archiveKey(std::string name) {
  for (std::size_t i = name.find('.'); i != std::string::npos; i = name.find('.', i)) name.replace(i, 1, "__");
  return name;
}

std::vector<std::pair<std::string, std::vector<int64_t>>> shapes(const torch::nn::Module& module) {
  std::vector<std::pair<std::string, std::vector<int64_t>>> s;
  for (const auto& p : module.named_parameters(/*recurse=*/true)) s.emplace_back(p.key(), p.value().sizes().vec());
  for (const auto& b : module.named_buffers(/*recurse=*/true)) s.emplace_back(b.key(), b.value().sizes().vec());
  return s;
}

// A value of the wrong type (yaml-cpp's BadConversion) is refused like any other bad metadata, naming the file.
ModelMetadata parseMetadata(const std::string& path, const ModelFormat& f, const std::string& text) {
  YAML::Node m;
  try {
    m = YAML::Load(text);
  } catch (const YAML::Exception& e) {
    bad(f.what, path, std::string("metadata is not valid YAML: ") + e.what());
  }
  if (!m.IsMap() || !m["format"] || m["format"].as<std::string>() != f.name)
    bad(f.what, path, "not an " + f.what + " model (metadata format is not '" + f.name + "')");
  ModelMetadata meta;
  meta.format_version = m["format_version"] ? m["format_version"].as<int>() : 0;
  if (meta.format_version != f.version)
    bad(f.what, path, "format version " + std::to_string(meta.format_version) + ", this build reads version " +
                          std::to_string(f.version));
  std::vector<std::string> classes;
  if (m["classes"]) classes = m["classes"].as<std::vector<std::string>>();
  std::vector<std::string> ours;
  for (ObjectClass c : kDetectedClasses) ours.push_back(className(c));
  if (classes != ours) {
    std::string got;
    for (const auto& c : classes) got += (got.empty() ? "" : ",") + c;
    bad(f.what, path, "trained for classes [" + got + "], this build detects [Car,Pedestrian,Cyclist]");
  }
  if (!m["basic_features"] || m["basic_features"].as<int>() != f.basic_features)
    bad(f.what, path, "built for another feature layout (basic_features is not " + std::to_string(f.basic_features) +
                          ")");
  if (m["trained_on"]) meta.trained_on = m["trained_on"].as<std::string>();
  if (!m["config"]) bad(f.what, path, "metadata has no config");
  YAML::Emitter e;
  e << m["config"];
  meta.config_yaml = e.c_str();
  return meta;
}

}  // namespace

void setTorchThreads(int threads) {
  if (threads > 0) torch::set_num_threads(threads);
}

void saveModelArchive(const std::string& path, const torch::nn::Module& module, const std::string& metadata_yaml,
                      ArchiveLayout layout) {
  const auto parent = std::filesystem::path(path).parent_path();
  if (!parent.empty()) std::filesystem::create_directories(parent);
  torch::serialize::OutputArchive ar;
  if (layout == ArchiveLayout::Nested) {
    module.save(ar);
  } else {
    // Flat: one entry per parameter/buffer under its dotted name with '.' spelt "__" (archive keys may not hold
    // dots), so loading can check each one by name and shape.
    for (const auto& p : module.named_parameters(/*recurse=*/true)) ar.write(archiveKey(p.key()), p.value());
    for (const auto& b : module.named_buffers(/*recurse=*/true)) ar.write(archiveKey(b.key()), b.value(), true);
  }
  ar.write(kMetaKey, c10::IValue(metadata_yaml));
  const std::string tmp = path + ".tmp";
  ar.save_to(tmp);
  std::filesystem::rename(tmp, path);
}

std::string readModelMetadata(const std::string& path, const std::string& what,
                              torch::serialize::InputArchive* archive) {
  if (!std::filesystem::is_regular_file(path)) bad(what, path, "no such file");
  try {
    archive->load_from(path);
  } catch (const std::exception& e) {
    bad(what, path, "cannot be read as a model archive (truncated or corrupt?): " + firstLine(e));
  }
  c10::IValue meta;
  bool ok = false;
  try {
    ok = archive->try_read(kMetaKey, meta);
  } catch (const std::exception&) {
    ok = false;
  }
  if (!ok || !meta.isString()) bad(what, path, "no " + what + " metadata (not a " + what + " model file)");
  return meta.toStringRef();
}

std::string modelMetadataYaml(const ModelFormat& format, const std::string& trained_on,
                              const std::string& config_yaml) {
  YAML::Emitter e;
  e << YAML::BeginMap;
  e << YAML::Key << "format" << YAML::Value << format.name;
  e << YAML::Key << "format_version" << YAML::Value << format.version;
  e << YAML::Key << "classes" << YAML::Value << YAML::Flow << YAML::BeginSeq;
  for (ObjectClass c : kDetectedClasses) e << className(c);
  e << YAML::EndSeq;
  e << YAML::Key << "basic_features" << YAML::Value << format.basic_features;
  e << YAML::Key << "trained_on" << YAML::Value << trained_on;
  e << YAML::Key << "config" << YAML::Value << YAML::Load(config_yaml);
  e << YAML::EndMap;
  return e.c_str();
}

ModelMetadata readCheckedMetadata(const std::string& path, const ModelFormat& format,
                                  torch::serialize::InputArchive* archive) {
  const std::string text = readModelMetadata(path, format.what, archive);
  try {
    return parseMetadata(path, format, text);
  } catch (const YAML::Exception& e) {
    bad(format.what, path, std::string("unreadable metadata: ") + e.what());
  }
}

void loadModelParameters(torch::serialize::InputArchive& archive, torch::nn::Module& module, const std::string& path,
                         const std::string& what, ArchiveLayout layout) {
  torch::NoGradGuard no_grad;
  if (layout == ArchiveLayout::Nested) {
    // torch's reader replaces each tensor by the one read, whatever its shape: the shapes are compared after.
    const auto expected = shapes(module);
    try {
      module.load(archive);
    } catch (const std::exception& e) {
      bad(what, path, "parameters do not fit the metadata's network shape: " + firstLine(e));
    }
    const auto got = shapes(module);
    for (std::size_t i = 0; i < expected.size(); ++i) {
      if (got[i].second != expected[i].second)
        bad(what, path, "parameter '" + got[i].first + "' has shape " + shapeString(got[i].second) +
                            ", the metadata's network needs " + shapeString(expected[i].second));
    }
    return;
  }
  auto check = [&](const std::string& name, torch::Tensor& t, bool is_buffer) {
    torch::Tensor read;
    bool ok = false;
    try {
      ok = archive.try_read(archiveKey(name), read, is_buffer);
    } catch (const std::exception&) {
      ok = false;
    }
    if (!ok) bad(what, path, "parameter '" + name + "' is missing (the file does not fit its metadata's network)");
    if (read.sizes() != t.sizes())
      bad(what, path, "parameter '" + name + "' has shape " + shapeString(read.sizes()) +
                          ", the metadata's network needs " + shapeString(t.sizes()));
    t.copy_(read);
  };
  for (auto& p : module.named_parameters(/*recurse=*/true)) check(p.key(), p.value(), false);
  for (auto& b : module.named_buffers(/*recurse=*/true)) check(b.key(), b.value(), true);
}

}  // namespace relation
}  // namespace ret3d
