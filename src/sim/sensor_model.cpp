#include "ret3d/sim/sensor_model.h"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <map>
#include <stdexcept>

#include "ret3d/core/yaml_reader.h"

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

WeakReturn weakReturn(const SensorModel& sensor, double signal) {
  WeakReturn w;
  const double zero = sensor.weak_return_zero_below, lost = sensor.weak_return_lost_below;
  if (signal >= zero) return w;
  w.zero = true;
  if (lost > 0 || zero > 0) w.lost = std::clamp((zero - signal) / std::max(zero - lost, 1e-9), 0.0, 1.0);
  return w;
}

static SensorModel readSensorModel(YamlReader r) {
  SensorModel s;
  s.source = r.origin();
  s.name = std::filesystem::path(r.origin()).stem().string();
  r.get("name", &s.name);
  r.get("motion_distortion", &s.motion_distortion);
  for (const auto& [key, value] : std::vector<std::pair<const char*, double*>>{
           {"azimuth_resolution_deg", &s.azimuth_resolution_deg}, {"rotation_rate_hz", &s.rotation_rate_hz},
           {"mount_height", &s.mount_height},                     {"mount_x", &s.mount_x},
           {"min_range", &s.min_range},                           {"max_range", &s.max_range},
           {"range_noise_sigma", &s.range_noise_sigma},           {"dropout", &s.dropout},
           {"far_dropout", &s.far_dropout},                       {"incidence_exponent", &s.incidence_exponent},
           {"range_attenuation", &s.range_attenuation},           {"intensity_gain", &s.intensity_gain},
           {"intensity_noise_sigma", &s.intensity_noise_sigma},   {"zero_intensity_below", &s.zero_intensity_below},
           {"zero_intensity_near", &s.zero_intensity_near},       {"zero_intensity_far", &s.zero_intensity_far},
           {"zero_intensity_near_range", &s.zero_intensity_near_range},
           {"zero_intensity_far_range", &s.zero_intensity_far_range},
           {"weak_return_zero_below", &s.weak_return_zero_below},
           {"weak_return_lost_below", &s.weak_return_lost_below}})
    r.get(key, value, -1e6, 1e6);
  if (r.get("elevation_deg", &s.elevation_deg)) {
    if (s.elevation_deg.empty()) r.fail("elevation_deg", "expected a list of angles");
    for (std::size_t i = 0; i < s.elevation_deg.size(); ++i)
      r.within("elevation_deg[" + std::to_string(i) + "]", s.elevation_deg[i], -90, 90);
  }
  if (r.get("ego_body_box", &s.ego_body_box)) {
    if (s.ego_body_box.size() != 6 && !s.ego_body_box.empty())
      r.fail("ego_body_box", "expected [x_min, x_max, y_min, y_max, z_min, z_max] or []");
    for (std::size_t i = 0; i < s.ego_body_box.size(); ++i)
      r.within("ego_body_box[" + std::to_string(i) + "]", s.ego_body_box[i], -100, 100);
    for (std::size_t a = 0; a < s.ego_body_box.size() / 2; ++a)
      if (s.ego_body_box[2 * a] >= s.ego_body_box[2 * a + 1]) r.fail("ego_body_box", "each min must be below its max");
  }
  // [{from: 2.0, to: -8.33, beams: 32}, ...]: beams evenly spaced from `from` to `to` inclusive.
  const bool has_blocks = r.has("elevation_blocks");
  std::vector<YamlReader> blocks = r.children("elevation_blocks");
  if (has_blocks && blocks.empty()) r.fail("elevation_blocks", "expected a list of {from, to, beams}");
  for (YamlReader& b : blocks) {
    double from = 0, to = 0, beams = 0;
    if (!b.get("from", &from, -90, 90) || !b.get("to", &to, -90, 90) || !b.get("beams", &beams, 1, 512))
      b.fail("", "needs from, to, beams");
    b.finish();
    const int n = static_cast<int>(beams);
    for (int i = 0; i < n; ++i) s.elevation_deg.push_back(n == 1 ? from : from + (to - from) * i / (n - 1));
  }
  r.finish();
  if (s.elevation_deg.empty()) r.fail("elevation_deg", "no beams given (elevation_deg or elevation_blocks)");
  if (s.azimuth_resolution_deg <= 0.01 || s.azimuth_resolution_deg > 10)
    r.fail("azimuth_resolution_deg", "must be in (0.01, 10]");
  if (s.rotation_rate_hz <= 0) r.fail("rotation_rate_hz", "must be positive");
  if (s.max_range <= s.min_range || s.min_range < 0) r.fail("max_range", "need 0 <= min_range < max_range");
  r.within("dropout", s.dropout, 0, 1);
  r.within("far_dropout", s.far_dropout, 0, 1);
  r.within("range_noise_sigma", s.range_noise_sigma, 0, YamlReader::kNoLimit);
  r.within("intensity_noise_sigma", s.intensity_noise_sigma, 0, YamlReader::kNoLimit);
  r.within("zero_intensity_below", s.zero_intensity_below, 0, 1);
  r.within("zero_intensity_far", s.zero_intensity_far, 0, 1);
  r.within("zero_intensity_near", s.zero_intensity_near, 0, 1);
  r.within("weak_return_zero_below", s.weak_return_zero_below, 0, 1);
  r.within("weak_return_lost_below", s.weak_return_lost_below, 0, 1);
  if (s.weak_return_lost_below > 0 && s.weak_return_lost_below >= s.weak_return_zero_below)
    r.fail("weak_return_lost_below", "must be below weak_return_zero_below");
  if (s.zero_intensity_far_range <= s.zero_intensity_near_range)
    r.fail("zero_intensity_far_range", "must be above zero_intensity_near_range");
  // Ring 0 is the lowest beam.
  std::sort(s.elevation_deg.begin(), s.elevation_deg.end());
  return s;
}

SensorModel loadSensorModel(const std::string& path) { return readSensorModel(YamlReader::load(path)); }

SensorModel sensorByName(const std::string& name, const std::string& package_root) {
  const std::string path = package_root + "/config/sensors/" + name + ".yaml";
  if (!std::filesystem::exists(path))
    throw std::runtime_error("unknown sensor '" + name + "': " + path + " does not exist (try hdl64e, vlp32c, os1_64)");
  return loadSensorModel(path);
}

}  // namespace sim
}  // namespace ret3d
