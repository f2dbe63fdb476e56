// Fuzz target: the YAML configuration loaders the nodelets and tools read. The first byte picks the loader, the rest is
// the file:
//   0 detector options (config/detector/*.yaml, also a model file's trained_with)   1 tracker options
//   2 IntraRM config   3 InterRM config   4 simulator scenario (config/sim)   5 sensor model (config/sensors)
// A loader must return or refuse with std::runtime_error / std::invalid_argument; a yaml-cpp exception escaping means
// the message does not say which file and key, and is a finding, as is a refusal of a file that does not name it
// (the tracker's value errors name the parameter instead). An accepted config must write out and read back the same.
#include <yaml-cpp/exceptions.h>

#include <stdexcept>

#include "fuzz_util.h"
#include "ret3d/detector/detector_options.h"
#include "ret3d/relation/inter_rm.h"
#include "ret3d/relation/intra_rm_config.h"
#include "ret3d/sim/sensor_model.h"
#include "ret3d/sim/sim_config.h"
#include "ret3d/tracking/tracker_options.h"

namespace {

using namespace ret3d;

template <typename Config>
void roundTrip(const Config& c, Config (*parse)(const std::string&, const std::string&), const char* what) {
  const std::string text = relation::toYaml(c);
  Config back;
  try {
    back = parse(text, "<round trip>");
  } catch (const std::exception& e) {
    fuzz::finding(std::string(what) + " config written by toYaml is refused: " + e.what() + "\n" + text);
  }
  if (relation::toYaml(back) != text) fuzz::finding(std::string(what) + " config changed in a round trip");
}

void load(std::uint8_t which, const std::string& path) {
  switch (which % 6) {
    case 0: {
      const DetectorOptions o = loadDetectorOptions(path);
      const std::string text = modelConfigToYaml(o.model);
      ModelConfig back;
      try {
        back = modelConfigFromYaml(text, "<round trip>");
      } catch (const std::exception& e) {
        fuzz::finding(std::string("model config written by modelConfigToYaml is refused: ") + e.what() + "\n" + text);
      }
      if (!diffModelConfigs(o.model, back).empty()) fuzz::finding("model config changed in a round trip");
      break;
    }
    case 1:
      validate(loadTrackerOptions(path));
      break;
    case 2:
      roundTrip<relation::IntraRMConfig>(relation::loadIntraRMConfig(path), relation::parseIntraRMConfig, "IntraRM");
      break;
    case 3:
      roundTrip<relation::InterRMConfig>(relation::loadInterRMConfig(path), relation::parseInterRMConfig, "InterRM");
      break;
    case 4:
      sim::loadSimConfig(path);
      break;
    case 5: {
      const sim::SensorModel s = sim::loadSensorModel(path);
      sim::nearestBeam(s, 0.0);
      break;
    }
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size < 1) return 0;
  const fuzz::TempFile file(".yaml", data + 1, size - 1);
  const bool names_file = data[0] % 6 != 1;
  try {
    load(data[0], file.path());
  } catch (const YAML::Exception& e) {
    fuzz::unexpectedException("config loader (yaml-cpp error not wrapped)", e);
  } catch (const std::runtime_error& e) {
    if (names_file) fuzz::expectNamesFile(e, file.path());
  } catch (const std::invalid_argument& e) {
    if (names_file) fuzz::expectNamesFile(e, file.path());
  } catch (const std::exception& e) {
    fuzz::unexpectedException("config loader", e);
  }
  return 0;
}
