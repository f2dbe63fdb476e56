// Spinning LiDAR models (config/sensors/*.yaml): beam elevations, azimuth resolution, rotation rate, mounting,
// range noise, drop-out, maximum range, the intensity model and optional motion distortion.
#pragma once

#include <string>
#include <vector>

namespace ret3d {
namespace sim {

struct SensorModel {
  std::string name;
  std::string source;                  // file it was read from
  std::vector<double> elevation_deg;   // one per beam, ring 0 = the lowest beam (as the velodyne driver numbers them)
  double azimuth_resolution_deg = 0.1728;
  double rotation_rate_hz = 10.0;
  double mount_height = 1.73;          // sensor above the ground (m)
  double mount_x = 0.0;                // sensor ahead of the ego box centre (m)
  double min_range = 2.5;              // returns closer than this are discarded (m)
  double max_range = 120.0;
  double range_noise_sigma = 0.02;     // m, Gaussian along the ray
  double dropout = 0.05;               // base probability a return is lost
  double far_dropout = 0.25;           // extra loss probability reached at max_range (weak far returns), linear in range
  // Intensity = reflectivity * cos(incidence)^incidence_exponent * exp(-range_attenuation * range) * gain
  //             + N(0, intensity_noise_sigma), clamped to [0, 1]. Lambertian for exponent 1.
  double incidence_exponent = 1.0;
  double range_attenuation = 0.004;    // 1/m
  double intensity_gain = 1.0;
  double intensity_noise_sigma = 0.03;
  bool motion_distortion = false;      // rays of one sweep leave from the pose at their own firing time
  // Zero-intensity returns (real HDL-64E scans report reflectance 0 for 10-16 % of their returns: dark and far
  // surfaces below the detector's threshold): a return whose intensity falls below `zero_intensity_below` keeps its
  // point with intensity 0, and so does one drawn with a probability going linearly from `zero_intensity_near` up to
  // `zero_intensity_near_range` (m) to `zero_intensity_far` from `zero_intensity_far_range` on. 0 = off.
  double zero_intensity_below = 0.0;
  double zero_intensity_near = 0.0;
  double zero_intensity_far = 0.0;
  double zero_intensity_near_range = 20.0;
  double zero_intensity_far_range = 50.0;
  // Detection floor on the signal before noise, reflectivity * cos(incidence)^k * exp(-a r) * gain: a return weaker
  // than `weak_return_zero_below` is reported with intensity 0 (the receiver barely triggers: black paint, tinted glass,
  // tyres), and is lost with a probability rising linearly from 0 there to 1 at `weak_return_lost_below`.
  // 0 = off.
  double weak_return_zero_below = 0.0;
  double weak_return_lost_below = 0.0;
  // The ego car's body around the sensor, an axis-aligned box [x_min, x_max, y_min, y_max, z_min, z_max] in the
  // LiDAR frame: rays passing through it return nothing (real scans' lowest beams hit the roof, hood and boot).
  // Empty = no body.
  std::vector<double> ego_body_box;

  int beams() const { return static_cast<int>(elevation_deg.size()); }
  int columns() const;                 // firings per revolution: round(360 / azimuth_resolution_deg)
  double period() const { return 1.0 / rotation_rate_hz; }
  // Whether a ray from the sensor along `dir` (LiDAR frame) passes through ego_body_box.
  bool blockedByEgoBody(double dx, double dy, double dz) const;
};

// The beam (ring) whose elevation is nearest `elevation_deg`, for scans without a ring (KITTI .bin); -1 without beams.
int nearestBeam(const SensorModel& sensor, double elevation_deg);

// What the detection floor does to a return of noiseless signal `signal`: the probability it is lost, and whether a
// kept one reads intensity 0.
struct WeakReturn {
  double lost = 0;
  bool zero = false;
};
WeakReturn weakReturn(const SensorModel& sensor, double signal);

// Reads a sensor YAML; the beams are an explicit `elevation_deg` list or `elevation_blocks` of evenly spaced beams.
// Throws std::runtime_error naming the file and key on bad input.
SensorModel loadSensorModel(const std::string& path);
// config/sensors/<name>.yaml under the package root `config_root` (the folder holding config/).
SensorModel sensorByName(const std::string& name, const std::string& package_root);

}  // namespace sim
}  // namespace ret3d
