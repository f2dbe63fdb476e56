// Fuzz target: the model-file loaders. The first byte picks the case, the rest is:
//   0 a detector model file as it is (src/detector/model_file.cpp: magic, version, lengths, checksum; truncation)
//   1 the metadata YAML of a detector model file, assembled with the repository model's weights and a valid checksum
//     (wrong versions, classes, anchors, shapes: a network the weights do not fit)
//   2 the metadata YAML of an IntraRM archive, 3 of an InterRM archive, each saved with the repository model's
//     parameters (src/relation/model_archive.cpp and the networks' loaders)
// The detector file is loaded the way the detector nodelet does (detectorOptionsForModel, then Detector). A loader
// must refuse with std::runtime_error / std::invalid_argument naming the file (ModelFileError is a runtime_error).
// The weights themselves are libtorch archives, parsed by libtorch's TorchScript importer, which is not robust
// against crafted archives (it crashes inside libtorch): the detector file's checksum keeps damaged weights from it,
// so the weights are never mutated here. With RET3D_FUZZ_WRITE_SEEDS=DIR the target writes its seeds (the
// repository models' metadata) into DIR at start-up (scripts/fuzz.sh).
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <stdexcept>

#include "fuzz_util.h"
#include "relation/inter_rm_network.h"
#include "relation/intra_rm_network.h"
#include "relation/model_archive.h"
#include "ret3d/detector/detector.h"
#include "ret3d/detector/model_file.h"

namespace {

using namespace ret3d;

const std::string kModels = std::string(RET3D_SOURCE_DIR) + "/models/lwd3d/";

// FNV-1a of everything before the trailing 8 bytes, stored there, as writeModelFile does.
std::string withChecksum(std::string s) {
  std::uint64_t h = 1469598103934665603ull;
  for (std::size_t i = 0; i + 8 < s.size(); ++i) {
    h ^= static_cast<unsigned char>(s[i]);
    h *= 1099511628211ull;
  }
  std::memcpy(&s[s.size() - 8], &h, 8);
  return s;
}

template <typename T>
void put(std::string* s, T v) {
  s->append(reinterpret_cast<const char*>(&v), sizeof(T));
}

std::string detectorFile(const std::string& metadata, const std::string& weights) {
  std::string out = "RET3DMDL";
  put<std::uint32_t>(&out, kModelFormatVersion);
  put<std::uint64_t>(&out, metadata.size());
  out += metadata;
  put<std::uint64_t>(&out, weights.size());
  out += weights;
  put<std::uint64_t>(&out, 0);
  return withChecksum(out);
}

struct RepositoryModels {
  ModelFileContents detector = readModelFile(kModels + "detector.pt");
  std::string detector_yaml = metadataToYaml(detector.metadata);
  relation::IntraRM intra{relation::IntraRMOptions{kModels + "intra_rm.pt"}};
  relation::InterRM inter{relation::InterRMOptions{kModels + "inter_rm.pt"}};
};

const RepositoryModels& models() {
  static const RepositoryModels m;
  return m;
}

void writeIntra(const std::string& path, const std::string& metadata) {
  torch::serialize::OutputArchive ar;
  models().intra.impl().net->save(ar);
  ar.write("ret3d_metadata", c10::IValue(metadata));
  ar.save_to(path);
}

void writeInter(const std::string& path, const std::string& metadata) {
  relation::saveModelArchive(path, *models().inter.impl().net, metadata);
}

template <typename Module, typename Options>
void loadModule(const std::string& path) {
  Options o;
  o.model_path = path;
  o.threads = 1;
  Module module(o);
}

void load(std::uint8_t which, const std::string& path) {
  switch (which % 4) {
    case 0:
    case 1: {
      DetectorOptions o = detectorOptionsForModel(path);
      o.inference.threads = 1;
      Detector detector(o);
      break;
    }
    case 2:
      loadModule<relation::IntraRM, relation::IntraRMOptions>(path);
      break;
    case 3:
      loadModule<relation::InterRM, relation::InterRMOptions>(path);
      break;
  }
}

}  // namespace

extern "C" int LLVMFuzzerInitialize(int*, char***) {
  relation::setTorchThreads(1);
  if (const char* dir = std::getenv("RET3D_FUZZ_WRITE_SEEDS")) {
    const auto write = [&](const std::string& name, const std::string& bytes) {
      std::ofstream(std::string(dir) + "/" + name, std::ios::binary) << bytes;
    };
    write("repo_detector_file", "0" + detectorFile(models().detector_yaml, models().detector.weights));
    write("repo_detector_metadata", "1" + models().detector_yaml);
    write("repo_intra_rm_metadata", "2" + relation::readModelMetadata(kModels + "intra_rm.pt", "IntraRM",
                                                                       std::make_unique<torch::serialize::InputArchive>().get()));
    write("repo_inter_rm_metadata", "3" + relation::readModelMetadata(kModels + "inter_rm.pt", "InterRM",
                                                                       std::make_unique<torch::serialize::InputArchive>().get()));
  }
  return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size < 1) return 0;
  const std::string rest(reinterpret_cast<const char*>(data) + 1, size - 1);
  const fuzz::TempFile file(".pt", data[0] % 4 == 0 ? rest : std::string());
  if (data[0] % 4 == 1) {
    std::ofstream(file.path(), std::ios::binary) << detectorFile(rest, models().detector.weights);
  } else if (data[0] % 4 == 2) {
    writeIntra(file.path(), rest);
  } else if (data[0] % 4 == 3) {
    writeInter(file.path(), rest);
  }
  try {
    load(data[0], file.path());
  } catch (const std::runtime_error& e) {
    fuzz::expectNamesFile(e, file.path());
  } catch (const std::invalid_argument& e) {
    fuzz::expectNamesFile(e, file.path());
  } catch (const std::exception& e) {
    fuzz::unexpectedException("model loader", e);
  }
  return 0;
}
