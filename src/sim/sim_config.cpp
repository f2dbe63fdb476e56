#include "ret3d/sim/sim_config.h"

#include <functional>
#include <stdexcept>
#include <vector>

#include <yaml-cpp/yaml.h>

#include "yaml_file.h"

namespace ret3d {
namespace sim {

std::map<std::string, MaterialConfig> defaultMaterials() {
  // Reflectivities chosen so the intensity histogram resembles KITTI's HDL-64E (docs/SIMULATOR.md): the road near 0.3,
  // bright paint and retro-reflective signs and plates, glass and foliage that often return nothing.
  return {
      {"asphalt", {0.28, 0.05, 0.0}},   {"marking", {0.60, 0.08, 0.0}},  {"concrete", {0.28, 0.04, 0.0}},
      {"curb", {0.30, 0.04, 0.0}},      {"terrain", {0.22, 0.06, 0.02}}, {"building", {0.25, 0.08, 0.0}},
      {"glass", {0.06, 0.03, 0.5}},     {"foliage", {0.20, 0.06, 0.35}}, {"bark", {0.25, 0.05, 0.0}},
      {"metal", {0.35, 0.08, 0.0}},     {"sign", {0.95, 0.04, 0.0}},     {"paint", {0.35, 0.15, 0.0}},
      {"car_glass", {0.05, 0.02, 0.6}}, {"tire", {0.05, 0.02, 0.05}},    {"plate", {0.95, 0.03, 0.0}},
      {"skin", {0.35, 0.05, 0.0}},      {"clothing", {0.25, 0.10, 0.0}},
  };
}

namespace {

// Walks a YAML map, dispatching known keys and rejecting unknown ones with the file and key path in the message.
class Reader {
 public:
  explicit Reader(std::string file) : file_(std::move(file)) {}

  [[noreturn]] void fail(const std::string& key, const std::string& what) const {
    throw std::runtime_error(file_ + ": key '" + key + "': " + what);
  }

  using Handler = std::function<void(const YAML::Node&, const std::string& key)>;
  void map(const YAML::Node& node, const std::string& prefix, const std::map<std::string, Handler>& handlers) const {
    if (!node.IsMap()) fail(prefix, "expected a map");
    for (const auto& kv : node) {
      const std::string k = kv.first.as<std::string>();
      const std::string full = prefix.empty() ? k : prefix + "." + k;
      auto it = handlers.find(k);
      if (it == handlers.end()) fail(full, "unknown key (typo?)");
      it->second(kv.second, full);
    }
  }

  Handler num(double& out, double lo = -1e18, double hi = 1e18) const {
    return [this, &out, lo, hi](const YAML::Node& n, const std::string& key) {
      try {
        out = n.as<double>();
      } catch (const YAML::Exception&) {
        fail(key, "expected a number (line " + std::to_string(n.Mark().line + 1) + ")");
      }
      if (!(out >= lo && out <= hi)) fail(key, "value " + std::to_string(out) + " outside [" + std::to_string(lo) +
                                                   ", " + std::to_string(hi) + "]");
    };
  }
  Handler integer(int& out, int lo, int hi) const {
    return [this, &out, lo, hi](const YAML::Node& n, const std::string& key) {
      try {
        out = n.as<int>();
      } catch (const YAML::Exception&) {
        fail(key, "expected an integer (line " + std::to_string(n.Mark().line + 1) + ")");
      }
      if (out < lo || out > hi) fail(key, "value outside [" + std::to_string(lo) + ", " + std::to_string(hi) + "]");
    };
  }
  Handler range(Range& out, double lo = -1e18, double hi = 1e18) const {
    return [this, &out, lo, hi](const YAML::Node& n, const std::string& key) {
      if (!n.IsSequence() || n.size() != 2) fail(key, "expected [lo, hi]");
      try {
        out.lo = n[0].as<double>();
        out.hi = n[1].as<double>();
      } catch (const YAML::Exception&) {
        fail(key, "expected two numbers");
      }
      if (out.lo > out.hi) fail(key, "lo > hi");
      if (out.lo < lo || out.hi > hi) fail(key, "range outside [" + std::to_string(lo) + ", " + std::to_string(hi) + "]");
    };
  }
  Handler str(std::string& out) const {
    return [this, &out](const YAML::Node& n, const std::string& key) {
      if (!n.IsScalar()) fail(key, "expected a string");
      out = n.as<std::string>();
    };
  }

 private:
  std::string file_;
};

}  // namespace

static SimConfig readSimConfig(const YAML::Node& root, const std::string& path) {
  SimConfig c;
  c.source = path;
  c.materials = defaultMaterials();
  Reader r(path);
  const double big = 1e6;
  RoadConfig& rd = c.road;
  GroundConfig& g = c.ground;
  ClutterConfig& cl = c.clutter;
  TrafficConfig& t = c.traffic;
  r.map(root, "", {
      {"name", r.str(c.name)},
      {"sensor", r.str(c.sensor)},
      {"frame_rate", r.num(c.frame_rate, 0.5, 100)},
      {"label_range", r.num(c.label_range, 1, 500)},
      {"label_min_points", r.integer(c.label_min_points, 0, 1000000)},
      {"mount_height_jitter", r.num(c.mount_height_jitter, 0, 0.5)},
      {"mount_tilt_jitter_deg", r.num(c.mount_tilt_jitter_deg, 0, 5)},
      {"road", [&](const YAML::Node& n, const std::string& k) {
         r.map(n, k, {
             {"lanes_per_direction", r.integer(rd.lanes_per_direction, 1, 6)},
             {"lane_width", r.num(rd.lane_width, 2.5, 5)},
             {"bike_lane_width", r.num(rd.bike_lane_width, 0, 4)},
             {"parking_lane_width", r.num(rd.parking_lane_width, 0, 4)},
             {"shoulder_width", r.num(rd.shoulder_width, 0, 6)},
             {"median_width", r.num(rd.median_width, 0, 20)},
             {"sidewalk_width", r.num(rd.sidewalk_width, 0, 10)},
             {"curb_height", r.num(rd.curb_height, 0, 0.4)},
             {"segment_length", r.range(rd.segment_length, 20, big)},
             {"curve_probability", r.num(rd.curve_probability, 0, 1)},
             {"curve_radius", r.range(rd.curve_radius, 20, big)},
             {"curve_angle_deg", r.range(rd.curve_angle_deg, 0, 90)},
             {"intersection_spacing", r.range(rd.intersection_spacing, 0, big)},
             {"cross_road_length", r.num(rd.cross_road_length, 20, 1000)},
             {"margin", r.num(rd.margin, 50, 1000)},
             {"marking_dash", r.num(rd.marking_dash, 0.5, 20)},
             {"marking_gap", r.num(rd.marking_gap, 0, 50)},
             {"crosswalk_spacing", r.num(rd.crosswalk_spacing, 0, big)},
         });
       }},
      {"ground", [&](const YAML::Node& n, const std::string& k) {
         r.map(n, k, {
             {"grid_cell", r.num(g.grid_cell, 0.25, 5)},
             {"road_roughness", r.num(g.road_roughness, 0, 0.2)},
             {"terrain_roughness", r.num(g.terrain_roughness, 0, 1)},
             {"roughness_wavelength", r.num(g.roughness_wavelength, 0.5, 100)},
             {"terrain_slope_max", r.num(g.terrain_slope_max, 0, 0.3)},
             {"terrain_step", r.num(g.terrain_step, 0, 10)},
         });
       }},
      {"clutter", [&](const YAML::Node& n, const std::string& k) {
         r.map(n, k, {
             {"building_probability", r.num(cl.building_probability, 0, 1)},
             {"building_setback", r.range(cl.building_setback, 0, 100)},
             {"building_frontage", r.range(cl.building_frontage, 2, 200)},
             {"building_depth", r.range(cl.building_depth, 2, 200)},
             {"building_height", r.range(cl.building_height, 1, 300)},
             {"building_gap", r.range(cl.building_gap, 0, 200)},
             {"wall_probability", r.num(cl.wall_probability, 0, 1)},
             {"wall_height", r.range(cl.wall_height, 0.2, 5)},
             {"fence_fraction", r.num(cl.fence_fraction, 0, 1)},
             {"tree_spacing", r.range(cl.tree_spacing, 1, big)},
             {"tree_trunk_radius", r.range(cl.tree_trunk_radius, 0.05, 2)},
             {"tree_trunk_height", r.range(cl.tree_trunk_height, 0.5, 10)},
             {"tree_crown_radius", r.range(cl.tree_crown_radius, 0.3, 10)},
             {"pole_spacing", r.range(cl.pole_spacing, 1, big)},
             {"pole_height", r.range(cl.pole_height, 1, 20)},
             {"sign_spacing", r.range(cl.sign_spacing, 1, big)},
             {"guard_rail", r.num(cl.guard_rail, 0, 1)},
             {"vegetation_setback", r.num(cl.vegetation_setback, 0, 100)},
             {"hedge_probability", r.num(cl.hedge_probability, 0, 1)},
             {"hedge_height", r.range(cl.hedge_height, 0.2, 5)},
             {"bush_spacing", r.range(cl.bush_spacing, 0, big)},
             {"bush_radius", r.range(cl.bush_radius, 0.1, 5)},
             {"bollard_spacing", r.range(cl.bollard_spacing, 0, big)},
         });
       }},
      {"traffic", [&](const YAML::Node& n, const std::string& k) {
         r.map(n, k, {
             {"ego_speed", r.range(t.ego_speed, 0, 40)},
             {"ego_lane", r.num(t.ego_lane, -1, 5)},
             {"car_density", r.num(t.car_density, 0, 20)},
             {"car_speed", r.range(t.car_speed, 0, 45)},
             {"parked_probability", r.num(t.parked_probability, 0, 1)},
             {"parked_on_cross_roads", r.num(t.parked_on_cross_roads, 0, 1)},
             {"pedestrian_density", r.num(t.pedestrian_density, 0, 100)},
             {"pedestrian_speed", r.range(t.pedestrian_speed, 0, 4)},
             {"pedestrian_standing", r.num(t.pedestrian_standing, 0, 1)},
             {"pedestrian_crossing", r.num(t.pedestrian_crossing, 0, 1)},
             {"cyclist_density", r.num(t.cyclist_density, 0, 50)},
             {"cyclist_speed", r.range(t.cyclist_speed, 0, 15)},
             {"turn_probability", r.num(t.turn_probability, 0, 1)},
             {"speed_change_interval", r.range(t.speed_change_interval, 0.1, 1000)},
             {"stop_probability", r.num(t.stop_probability, 0, 1)},
             {"traffic_light_cycle", r.num(t.traffic_light_cycle, 0, 600)},
             {"sedan", r.num(t.sedan, 0, 1)},
             {"hatchback", r.num(t.hatchback, 0, 1)},
             {"suv", r.num(t.suv, 0, 1)},
             {"van", r.num(t.van, 0, 1)},
         });
       }},
      {"materials", [&](const YAML::Node& n, const std::string& k) {
         if (!n.IsMap()) r.fail(k, "expected a map of materials");
         for (const auto& kv : n) {
           const std::string name = kv.first.as<std::string>();
           auto it = c.materials.find(name);
           if (it == c.materials.end()) r.fail(k + "." + name, "unknown material");
           MaterialConfig& m = it->second;
           r.map(kv.second, k + "." + name, {
               {"reflectivity", r.num(m.reflectivity, 0, 1)},
               {"sigma", r.num(m.sigma, 0, 1)},
               {"dropout", r.num(m.dropout, 0, 1)},
               {"porosity", r.num(m.porosity, 0, 1)},
           });
         }
       }},
  });
  if (t.sedan + t.hatchback + t.suv + t.van <= 0) r.fail("traffic.sedan", "body type mix sums to zero");
  return c;
}

SimConfig loadSimConfig(const std::string& path) {
  return readYamlFile<SimConfig>(path, readSimConfig);
}

}  // namespace sim
}  // namespace ret3d
