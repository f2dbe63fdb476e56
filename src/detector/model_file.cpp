#include "ret3d/detector/model_file.h"

#include <cstring>
#include <ctime>
#include <fstream>
#include <sstream>

#include <yaml-cpp/yaml.h>

namespace ret3d {

namespace {

constexpr char kMagic[8] = {'R', 'E', 'T', '3', 'D', 'M', 'D', 'L'};

std::uint64_t fnv1a(const std::string& data) {
  std::uint64_t h = 1469598103934665603ull;
  for (unsigned char c : data) {
    h ^= c;
    h *= 1099511628211ull;
  }
  return h;
}

template <typename T>
void put(std::string* s, T v) {
  s->append(reinterpret_cast<const char*>(&v), sizeof(T));
}

}  // namespace

std::string metadataToYaml(const ModelMetadata& m) {
  YAML::Emitter e;
  e.SetDoublePrecision(17);  // anchors restored bit-exactly
  e << YAML::BeginMap;
  e << YAML::Key << "format_version" << YAML::Value << m.format_version;
  e << YAML::Key << "model" << YAML::Value << YAML::Load(modelConfigToYaml(m.config));
  e << YAML::Key << "anchors" << YAML::Value << YAML::BeginSeq;
  for (const Anchor& a : m.anchors) {
    e << YAML::Flow << YAML::BeginMap << YAML::Key << "class" << YAML::Value << className(a.label) << YAML::Key
      << "length" << YAML::Value << a.length << YAML::Key << "width" << YAML::Value << a.width << YAML::Key
      << "height" << YAML::Value << a.height << YAML::Key << "z" << YAML::Value << a.z << YAML::Key << "stride"
      << YAML::Value << a.stride << YAML::EndMap;
  }
  e << YAML::EndSeq;
  e << YAML::Key << "in_channels" << YAML::Value << m.in_channels;
  e << YAML::Key << "feature_dim" << YAML::Value << m.feature_dim;
  e << YAML::Key << "feature_stride" << YAML::Value << m.feature_stride;
  e << YAML::Key << "parameter_count" << YAML::Value << m.parameter_count;
  e << YAML::Key << "created" << YAML::Value << m.created;
  e << YAML::Key << "trained_with" << YAML::Value << YAML::Literal << m.trained_with;
  e << YAML::EndMap;
  return e.c_str();
}

ModelMetadata metadataFromYaml(const std::string& yaml, const std::string& origin) {
  ModelMetadata m;
  try {
    const YAML::Node n = YAML::Load(yaml);
    m.format_version = n["format_version"].as<std::uint32_t>();
    m.config = modelConfigFromYaml(YAML::Dump(n["model"]), origin + " (metadata)");
    for (const auto& a : n["anchors"]) {
      Anchor an;
      const auto c = classFromName(a["class"].as<std::string>());
      if (!c) throw ModelFileError(origin + ": metadata: anchor of unknown class " + a["class"].as<std::string>());
      an.label = *c;
      an.length = a["length"].as<double>();
      an.width = a["width"].as<double>();
      an.height = a["height"].as<double>();
      an.z = a["z"].as<double>();
      an.stride = a["stride"].as<int>();
      m.anchors.push_back(an);
    }
    m.in_channels = n["in_channels"].as<int>();
    m.feature_dim = n["feature_dim"].as<int>();
    m.feature_stride = n["feature_stride"].as<int>();
    m.parameter_count = n["parameter_count"].as<std::int64_t>();
    if (n["created"]) m.created = n["created"].as<std::string>();
    if (n["trained_with"]) m.trained_with = n["trained_with"].as<std::string>();
  } catch (const YAML::Exception& e) {
    throw ModelFileError(origin + ": unreadable metadata: " + e.what());
  } catch (const std::runtime_error& e) {
    throw ModelFileError(origin + ": unreadable metadata: " + e.what());
  }
  return m;
}

void writeModelFile(const std::string& path, const ModelMetadata& metadata, const std::string& weights) {
  ModelMetadata m = metadata;
  if (m.created.empty()) {
    char buf[32];
    const std::time_t t = std::time(nullptr);
    std::strftime(buf, sizeof(buf), "%Y-%m-%dT%H:%M:%SZ", std::gmtime(&t));
    m.created = buf;
  }
  const std::string meta = metadataToYaml(m);
  std::string out(kMagic, sizeof(kMagic));
  put<std::uint32_t>(&out, m.format_version);
  put<std::uint64_t>(&out, meta.size());
  out += meta;
  put<std::uint64_t>(&out, weights.size());
  out += weights;
  put<std::uint64_t>(&out, fnv1a(out));
  // Write to a temporary name and rename, so an interrupted save never leaves a half-written model behind.
  const std::string tmp = path + ".tmp";
  {
    std::ofstream f(tmp, std::ios::binary | std::ios::trunc);
    if (!f) throw ModelFileError(path + ": cannot write model file");
    f.write(out.data(), static_cast<std::streamsize>(out.size()));
    if (!f) throw ModelFileError(path + ": write failed");
  }
  if (std::rename(tmp.c_str(), path.c_str()) != 0) throw ModelFileError(path + ": cannot rename " + tmp);
}

ModelFileContents readModelFile(const std::string& path) {
  std::ifstream f(path, std::ios::binary);
  if (!f) throw ModelFileError(path + ": cannot open model file");
  std::stringstream ss;
  ss << f.rdbuf();
  const std::string s = ss.str();
  auto fail = [&](const std::string& m) { throw ModelFileError(path + ": " + m); };
  if (s.size() < sizeof(kMagic) || std::memcmp(s.data(), kMagic, sizeof(kMagic)) != 0)
    fail("not a ret3d model file (no RET3DMDL header)");
  std::size_t pos = sizeof(kMagic);
  auto need = [&](std::size_t n, const char* what) {
    if (s.size() < pos + n)
      fail(std::string("truncated: ") + what + " needs " + std::to_string(n) + " bytes at offset " +
           std::to_string(pos) + ", the file has " + std::to_string(s.size()) + " bytes");
  };
  auto get64 = [&](const char* what) {
    need(8, what);
    std::uint64_t v;
    std::memcpy(&v, s.data() + pos, 8);
    pos += 8;
    return v;
  };
  need(4, "the format version");
  std::uint32_t version;
  std::memcpy(&version, s.data() + pos, 4);
  pos += 4;
  if (version != kModelFormatVersion)
    fail("format version " + std::to_string(version) + ", this build reads version " +
         std::to_string(kModelFormatVersion));
  const std::uint64_t meta_len = get64("the metadata length");
  need(meta_len, "the metadata");
  const std::string meta = s.substr(pos, meta_len);
  pos += meta_len;
  const std::uint64_t weights_len = get64("the weights length");
  need(weights_len, "the weights");
  ModelFileContents out;
  out.weights = s.substr(pos, weights_len);
  pos += weights_len;
  const std::size_t checked = pos;
  const std::uint64_t sum = get64("the checksum");
  if (pos != s.size()) fail(std::to_string(s.size() - pos) + " unexpected bytes after the checksum");
  if (sum != fnv1a(s.substr(0, checked))) fail("corrupt: checksum mismatch");
  out.metadata = metadataFromYaml(meta, path);
  return out;
}

std::vector<std::string> checkModelMetadata(const ModelMetadata& file, const ModelConfig& expected) {
  std::vector<std::string> diffs;
  for (auto& d : diffModelConfigs(file.config, expected)) diffs.push_back(d + " (file vs config)");
  return diffs;
}

DetectorOptions detectorOptionsForModel(const std::string& model_path, const std::string& config_yaml) {
  DetectorOptions o;
  if (!config_yaml.empty()) {
    o = loadDetectorOptions(config_yaml);
  } else {
    const ModelFileContents file = readModelFile(model_path);
    if (file.metadata.trained_with.empty())
      throw ModelFileError(model_path + ": the file does not store the config it was trained with; give a detector config YAML");
    o = detectorOptionsFromYaml(file.metadata.trained_with, model_path + " (trained_with)");
  }
  o.inference.model_path = model_path;
  return o;
}

}  // namespace ret3d
