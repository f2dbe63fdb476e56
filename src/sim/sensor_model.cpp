#include "ret3d/sim/sensor_model.h"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <map>
#include <stdexcept>

#include <yaml-cpp/yaml.h>

#include "yaml_file.h"

namespace ret3d {
namespace sim {

int SensorModel::columns() const { return static_cast<int>(std::lround(360.0 / azimuth_resolution_deg)); }

bool SensorModel::blockedByEgoBody(double dx, double dy, double dz) const {
  if (ego_body_box.size() != 6) return false;
  // Slab test of the ray from the origin, t in [0, inf).
  double t0 = 0, t1 = 1e30;
  const double d[3] = {dx, dy, dz};
  for (int a = 0; a < 3; ++a) {
    const double lo = ego_body_box[2 * a], hi = ego_body_box[2 * a + 1];
    if (std::abs(d[a]) < 1e-12) {
      if (0 < lo || 0 > hi) return false;
      continue;
    }
    double ta = lo / d[a], tb = hi / d[a];
    if (ta > tb) std::swap(ta, tb);
    t0 = std::max(t0, ta);
    t1 = std::min(t1, tb);
    if (t0 > t1) return false;
  }
  return true;
}

int nearestBeam(const SensorModel& sensor, double elevation_deg) {
  const auto& el = sensor.elevation_deg;  // ascending
  if (el.empty()) return -1;
  const auto it = std::lower_bound(el.begin(), el.end(), elevation_deg);
  std::size_t ring = static_cast<std::size_t>(it - el.begin());
  if (ring == el.size() || (ring > 0 && elevation_deg - el[ring - 1] < el[ring] - elevation_deg))
    ring = ring > 0 ? ring - 1 : 0;
  return static_cast<int>(ring);
}

namespace {

[[noreturn]] void fail(const std::string& file, const std::string& key, const std::string& what) {
  throw std::runtime_error(file + ": key '" + key + "': " + what);
}

double number(const std::string& file, const YAML::Node& n, const std::string& key, double lo, double hi) {
  double v = 0;
  try {
    v = n.as<double>();
  } catch (const YAML::Exception&) {
    fail(file, key, "expected a number (line " + std::to_string(n.Mark().line + 1) + ")");
  }
  if (!(v >= lo && v <= hi)) fail(file, key, "value " + std::to_string(v) + " outside [" + std::to_string(lo) + ", " +
                                                 std::to_string(hi) + "]");
  return v;
}

}  // namespace

static SensorModel readSensorModel(const YAML::Node& root, const std::string& path) {
  if (!root.IsMap()) fail(path, "", "expected a map");
  SensorModel s;
  s.source = path;
  s.name = std::filesystem::path(path).stem().string();
  const std::map<std::string, double*> numbers = {
      {"azimuth_resolution_deg", &s.azimuth_resolution_deg}, {"rotation_rate_hz", &s.rotation_rate_hz},
      {"mount_height", &s.mount_height},                     {"mount_x", &s.mount_x},
      {"min_range", &s.min_range},                           {"max_range", &s.max_range},
      {"range_noise_sigma", &s.range_noise_sigma},           {"dropout", &s.dropout},
      {"far_dropout", &s.far_dropout},                       {"incidence_exponent", &s.incidence_exponent},
      {"range_attenuation", &s.range_attenuation},           {"intensity_gain", &s.intensity_gain},
      {"intensity_noise_sigma", &s.intensity_noise_sigma},   {"zero_intensity_below", &s.zero_intensity_below},
      {"zero_intensity_near", &s.zero_intensity_near},       {"zero_intensity_far", &s.zero_intensity_far},
      {"zero_intensity_near_range", &s.zero_intensity_near_range},
      {"zero_intensity_far_range", &s.zero_intensity_far_range}};
  for (const auto& kv : root) {
    const std::string key = kv.first.as<std::string>();
    const YAML::Node& v = kv.second;
    if (key == "name") {
      s.name = v.as<std::string>();
    } else if (key == "motion_distortion") {
      try {
        s.motion_distortion = v.as<bool>();
      } catch (const YAML::Exception&) {
        fail(path, key, "expected true or false");
      }
    } else if (key == "elevation_deg") {
      if (!v.IsSequence() || v.size() == 0) fail(path, key, "expected a list of angles");
      for (std::size_t i = 0; i < v.size(); ++i)
        s.elevation_deg.push_back(number(path, v[i], key + "[" + std::to_string(i) + "]", -90, 90));
    } else if (key == "ego_body_box") {
      if (!v.IsSequence() || (v.size() != 6 && v.size() != 0))
        fail(path, key, "expected [x_min, x_max, y_min, y_max, z_min, z_max] or []");
      for (std::size_t i = 0; i < v.size(); ++i)
        s.ego_body_box.push_back(number(path, v[i], key + "[" + std::to_string(i) + "]", -100, 100));
      for (int a = 0; a < static_cast<int>(s.ego_body_box.size()) / 2; ++a)
        if (s.ego_body_box[2 * a] >= s.ego_body_box[2 * a + 1]) fail(path, key, "each min must be below its max");
    } else if (key == "elevation_blocks") {
      // [{from: 2.0, to: -8.33, beams: 32}, ...]: beams evenly spaced from `from` to `to` inclusive.
      if (!v.IsSequence() || v.size() == 0) fail(path, key, "expected a list of {from, to, beams}");
      for (std::size_t i = 0; i < v.size(); ++i) {
        const std::string k = key + "[" + std::to_string(i) + "]";
        if (!v[i].IsMap() || !v[i]["from"] || !v[i]["to"] || !v[i]["beams"]) fail(path, k, "needs from, to, beams");
        const double from = number(path, v[i]["from"], k + ".from", -90, 90);
        const double to = number(path, v[i]["to"], k + ".to", -90, 90);
        const int n = static_cast<int>(number(path, v[i]["beams"], k + ".beams", 1, 512));
        for (int b = 0; b < n; ++b) s.elevation_deg.push_back(n == 1 ? from : from + (to - from) * b / (n - 1));
      }
    } else if (numbers.count(key)) {
      *numbers.at(key) = number(path, v, key, -1e6, 1e6);
    } else {
      fail(path, key, "unknown key (typo?)");
    }
  }
  if (s.elevation_deg.empty()) fail(path, "elevation_deg", "no beams given (elevation_deg or elevation_blocks)");
  if (s.azimuth_resolution_deg <= 0.01 || s.azimuth_resolution_deg > 10) fail(path, "azimuth_resolution_deg", "must be in (0.01, 10]");
  if (s.rotation_rate_hz <= 0) fail(path, "rotation_rate_hz", "must be positive");
  if (s.max_range <= s.min_range || s.min_range < 0) fail(path, "max_range", "need 0 <= min_range < max_range");
  if (s.dropout < 0 || s.dropout > 1 || s.far_dropout < 0 || s.far_dropout > 1) fail(path, "dropout", "must be in [0, 1]");
  if (s.range_noise_sigma < 0 || s.intensity_noise_sigma < 0) fail(path, "range_noise_sigma", "must be >= 0");
  if (s.zero_intensity_below < 0 || s.zero_intensity_below > 1) fail(path, "zero_intensity_below", "must be in [0, 1]");
  if (s.zero_intensity_far < 0 || s.zero_intensity_far > 1) fail(path, "zero_intensity_far", "must be in [0, 1]");
  if (s.zero_intensity_near < 0 || s.zero_intensity_near > 1) fail(path, "zero_intensity_near", "must be in [0, 1]");
  if (s.zero_intensity_far_range <= s.zero_intensity_near_range)
    fail(path, "zero_intensity_far_range", "must be above zero_intensity_near_range");
  // Ring 0 is the lowest beam.
  std::sort(s.elevation_deg.begin(), s.elevation_deg.end());
  return s;
}

SensorModel loadSensorModel(const std::string& path) {
  return readYamlFile<SensorModel>(path, readSensorModel);
}

SensorModel sensorByName(const std::string& name, const std::string& package_root) {
  const std::string path = package_root + "/config/sensors/" + name + ".yaml";
  if (!std::filesystem::exists(path))
    throw std::runtime_error("unknown sensor '" + name + "': " + path + " does not exist (try hdl64e, vlp32c, os1_64)");
  return loadSensorModel(path);
}

}  // namespace sim
}  // namespace ret3d
