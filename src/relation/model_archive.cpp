#include "model_archive.h"

#include <filesystem>
#include <stdexcept>

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

}  // namespace

void saveModelArchive(const std::string& path, const torch::nn::Module& module, const std::string& metadata_yaml) {
  const auto parent = std::filesystem::path(path).parent_path();
  if (!parent.empty()) std::filesystem::create_directories(parent);
  // Flat: one entry per parameter/buffer under its dotted name with '.' spelt "__" (archive keys may not hold dots),
  // so loading can check each one by name and shape.
  torch::serialize::OutputArchive ar;
  for (const auto& p : module.named_parameters(/*recurse=*/true)) ar.write(archiveKey(p.key()), p.value());
  for (const auto& b : module.named_buffers(/*recurse=*/true)) ar.write(archiveKey(b.key()), b.value(), true);
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

void loadModelParameters(torch::serialize::InputArchive& archive, torch::nn::Module& module, const std::string& path,
                         const std::string& what) {
  torch::NoGradGuard no_grad;
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
