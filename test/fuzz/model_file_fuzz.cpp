// Fuzz target: the model-file loaders. The first byte picks the loader, the rest is the file:
//   0 detector model file as it is (src/detector/model_file.cpp; the RET3DMDL layout and its checksum)
//   1 the same with its trailing checksum recomputed by this target, so mutations reach the metadata and weights
//   2 IntraRM model archive   3 InterRM model archive (src/relation/model_archive.cpp and the networks' loaders)
// The detector file is loaded the way the detector nodelet does (detectorOptionsForModel, then Detector). A loader must
// refuse a truncated file, another version or weights of other shapes with std::runtime_error /
// std::invalid_argument (ModelFileError is a runtime_error); anything else is a finding.
#include <cstring>
#include <stdexcept>

#include "fuzz_util.h"
#include "ret3d/detector/detector.h"
#include "ret3d/detector/model_file.h"
#include "ret3d/relation/inter_rm.h"
#include "ret3d/relation/intra_rm.h"

namespace {

using namespace ret3d;

// FNV-1a of the file's bytes before the checksum, as writeModelFile stores it.
std::string withChecksum(std::string s) {
  if (s.size() < 8) return s;
  std::uint64_t h = 1469598103934665603ull;
  for (std::size_t i = 0; i < s.size() - 8; ++i) {
    h ^= static_cast<unsigned char>(s[i]);
    h *= 1099511628211ull;
  }
  std::memcpy(&s[s.size() - 8], &h, 8);
  return s;
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

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size < 1) return 0;
  std::string bytes(reinterpret_cast<const char*>(data) + 1, size - 1);
  if (data[0] % 4 == 1) bytes = withChecksum(std::move(bytes));
  const fuzz::TempFile file(".pt", bytes);
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
