#include "ret3d/sim/sim_config.h"

#include <stdexcept>
#include <vector>

#include "ret3d/core/yaml_reader.h"

namespace ret3d {
namespace sim {

std::map<std::string, MaterialConfig> defaultMaterials() {
  // Reflectivities chosen so the intensity histogram resembles KITTI's HDL-64E (docs/SIMULATOR.md): the road near 0.3,
  // bright paint and retro-reflective signs and plates, glass and foliage that often return nothing; a car's windows
  // return weakly from the cabin behind them.
  return {
      {"asphalt", {0.28, 0.05, 0.0}},   {"marking", {0.60, 0.08, 0.0}},  {"concrete", {0.28, 0.04, 0.0}},
      {"curb", {0.30, 0.04, 0.0}},      {"terrain", {0.22, 0.06, 0.02}}, {"building", {0.25, 0.08, 0.0}},
      {"glass", {0.06, 0.03, 0.5}},     {"foliage", {0.20, 0.06, 0.35}}, {"bark", {0.25, 0.05, 0.0}},
      {"metal", {0.35, 0.08, 0.0}},     {"sign", {0.95, 0.04, 0.0}},     {"paint", {0.35, 0.15, 0.0}},
      {"car_glass", {0.07, 0.02, 0.0}}, {"tire", {0.05, 0.02, 0.05}},    {"plate", {0.95, 0.03, 0.0}},
      {"skin", {0.35, 0.05, 0.0}},      {"clothing", {0.25, 0.10, 0.0}},
  };
}

namespace {

constexpr double kBig = 1e6;  // the upper bound of lengths and spacings that have no practical one

// A range [lo, hi] whose ends lie in [min, max].
void readRange(YamlReader& r, const std::string& key, Range* out, double min, double max) {
  std::vector<double> v;
  if (!r.get(key, &v)) return;
  if (v.size() != 2) r.fail(key, "expected [lo, hi]");
  if (v[0] > v[1]) r.fail(key, "lo > hi");
  r.within(key, v[0], min, max);
  r.within(key, v[1], min, max);
  *out = {v[0], v[1]};
}

void readRoad(YamlReader r, RoadConfig* o) {
  r.get("lanes_per_direction", &o->lanes_per_direction, 1, 6);
  r.get("lane_width", &o->lane_width, 2.5, 5);
  r.get("bike_lane_width", &o->bike_lane_width, 0, 4);
  r.get("parking_lane_width", &o->parking_lane_width, 0, 4);
  r.get("shoulder_width", &o->shoulder_width, 0, 6);
  r.get("median_width", &o->median_width, 0, 20);
  r.get("sidewalk_width", &o->sidewalk_width, 0, 10);
  r.get("curb_height", &o->curb_height, 0, 0.4);
  readRange(r, "segment_length", &o->segment_length, 20, kBig);
  r.get("curve_probability", &o->curve_probability, 0, 1);
  readRange(r, "curve_radius", &o->curve_radius, 20, kBig);
  readRange(r, "curve_angle_deg", &o->curve_angle_deg, 0, 90);
  readRange(r, "intersection_spacing", &o->intersection_spacing, 0, kBig);
  r.get("cross_road_length", &o->cross_road_length, 20, 1000);
  r.get("margin", &o->margin, 50, 1000);
  r.get("marking_dash", &o->marking_dash, 0.5, 20);
  r.get("marking_gap", &o->marking_gap, 0, 50);
  r.get("crosswalk_spacing", &o->crosswalk_spacing, 0, kBig);
  readRange(r, "hill_amplitude", &o->hill_amplitude, 0, 20);
  readRange(r, "hill_wavelength", &o->hill_wavelength, 20, kBig);
  r.finish();
}

void readGround(YamlReader r, GroundConfig* o) {
  r.get("grid_cell", &o->grid_cell, 0.25, 5);
  r.get("road_roughness", &o->road_roughness, 0, 0.2);
  r.get("terrain_roughness", &o->terrain_roughness, 0, 1);
  r.get("roughness_wavelength", &o->roughness_wavelength, 0.5, 100);
  r.get("terrain_slope_max", &o->terrain_slope_max, 0, 0.3);
  r.get("terrain_step", &o->terrain_step, 0, 10);
  r.finish();
}

void readClutter(YamlReader r, ClutterConfig* o) {
  r.get("building_probability", &o->building_probability, 0, 1);
  readRange(r, "building_setback", &o->building_setback, 0, 100);
  readRange(r, "building_frontage", &o->building_frontage, 2, 200);
  readRange(r, "building_depth", &o->building_depth, 2, 200);
  readRange(r, "building_height", &o->building_height, 1, 300);
  readRange(r, "building_gap", &o->building_gap, 0, 200);
  r.get("wall_probability", &o->wall_probability, 0, 1);
  readRange(r, "wall_height", &o->wall_height, 0.2, 5);
  r.get("fence_fraction", &o->fence_fraction, 0, 1);
  readRange(r, "tree_spacing", &o->tree_spacing, 1, kBig);
  readRange(r, "tree_trunk_radius", &o->tree_trunk_radius, 0.05, 2);
  readRange(r, "tree_trunk_height", &o->tree_trunk_height, 0.5, 10);
  readRange(r, "tree_crown_radius", &o->tree_crown_radius, 0.3, 10);
  readRange(r, "pole_spacing", &o->pole_spacing, 1, kBig);
  readRange(r, "pole_height", &o->pole_height, 1, 20);
  readRange(r, "sign_spacing", &o->sign_spacing, 1, kBig);
  r.get("guard_rail", &o->guard_rail, 0, 1);
  r.get("vegetation_setback", &o->vegetation_setback, 0, 100);
  r.get("hedge_probability", &o->hedge_probability, 0, 1);
  readRange(r, "hedge_height", &o->hedge_height, 0.2, 5);
  readRange(r, "bush_spacing", &o->bush_spacing, 0, kBig);
  readRange(r, "bush_radius", &o->bush_radius, 0.1, 5);
  readRange(r, "bollard_spacing", &o->bollard_spacing, 0, kBig);
  readRange(r, "pole_radius", &o->pole_radius, 0.02, 1);
  readRange(r, "sign_height", &o->sign_height, 1, 8);
  readRange(r, "sign_plate", &o->sign_plate, 0.1, 3);
  readRange(r, "bollard_radius", &o->bollard_radius, 0.02, 1);
  readRange(r, "bollard_height", &o->bollard_height, 0.1, 3);
  readRange(r, "post_spacing", &o->post_spacing, 0, kBig);
  readRange(r, "post_radius", &o->post_radius, 0.01, 0.5);
  readRange(r, "post_height", &o->post_height, 0.3, 10);
  readRange(r, "bicycle_spacing", &o->bicycle_spacing, 0, kBig);
  r.get("railing_probability", &o->railing_probability, 0, 1);
  readRange(r, "railing_height", &o->railing_height, 0.3, 3);
  r.get("low_wall_probability", &o->low_wall_probability, 0, 1);
  readRange(r, "low_wall_height", &o->low_wall_height, 0.1, 2);
  r.finish();
}

void readQueue(YamlReader r, QueueConfig* o) {
  r.get("probability", &o->probability, 0, 1);
  readRange(r, "ahead", &o->ahead, 0, 50);
  readRange(r, "behind", &o->behind, 0, 50);
  readRange(r, "gap", &o->gap, 0.5, 20);
  readRange(r, "speed", &o->speed, 0, 20);
  r.get("stop_probability", &o->stop_probability, 0, 1);
  r.get("headway", &o->headway, 0.1, 5);
  r.finish();
}

void readTraffic(YamlReader r, TrafficConfig* o) {
  readRange(r, "ego_speed", &o->ego_speed, 0, 40);
  r.get("ego_lane", &o->ego_lane, -1, 5);
  r.get("car_density", &o->car_density, 0, 20);
  readRange(r, "car_speed", &o->car_speed, 0, 45);
  r.get("parked_probability", &o->parked_probability, 0, 1);
  r.get("parked_on_cross_roads", &o->parked_on_cross_roads, 0, 1);
  r.get("pedestrian_density", &o->pedestrian_density, 0, 100);
  readRange(r, "pedestrian_speed", &o->pedestrian_speed, 0, 4);
  r.get("pedestrian_standing", &o->pedestrian_standing, 0, 1);
  r.get("pedestrian_crossing", &o->pedestrian_crossing, 0, 1);
  r.get("cyclist_density", &o->cyclist_density, 0, 50);
  readRange(r, "cyclist_speed", &o->cyclist_speed, 0, 15);
  r.get("turn_probability", &o->turn_probability, 0, 1);
  readRange(r, "speed_change_interval", &o->speed_change_interval, 0.1, 1000);
  r.get("stop_probability", &o->stop_probability, 0, 1);
  r.get("traffic_light_cycle", &o->traffic_light_cycle, 0, 600);
  r.get("sedan", &o->sedan, 0, 1);
  r.get("hatchback", &o->hatchback, 0, 1);
  r.get("suv", &o->suv, 0, 1);
  r.get("van", &o->van, 0, 1);
  r.get("truck", &o->truck, 0, 1);
  r.get("delivery_van", &o->delivery_van, 0, 1);
  if (r.has("queue")) readQueue(r.child("queue"), &o->queue);
  r.finish();
  if (o->truck + o->delivery_van > 1) r.fail("delivery_van", "truck + delivery_van above 1");
}

void readPaint(YamlReader& r, std::vector<PaintMode>* out) {
  const bool has = r.has("paint");
  std::vector<YamlReader> modes = r.children("paint");
  if (has && modes.empty()) r.fail("paint", "expected a list of {weight, reflectivity: [lo, hi]}");
  double total = 0;
  for (YamlReader& m : modes) {
    PaintMode p;
    m.get("weight", &p.weight, 0, 1000);
    readRange(m, "reflectivity", &p.reflectivity, 0.0, 1.0);
    m.finish();
    total += p.weight;
    out->push_back(p);
  }
  if (has && total <= 0) r.fail("paint", "the weights sum to zero");
}

void readMaterials(YamlReader r, std::map<std::string, MaterialConfig>* materials) {
  for (const std::string& name : r.keys()) {
    auto it = materials->find(name);
    if (it == materials->end()) {
      std::string known;
      for (const auto& [known_name, config] : *materials) known += (known.empty() ? "" : ", ") + known_name;
      r.fail(name, "unknown material (known: " + known + ")");
    }
    YamlReader m = r.child(name);
    m.get("reflectivity", &it->second.reflectivity, 0, 1);
    m.get("sigma", &it->second.sigma, 0, 1);
    m.get("dropout", &it->second.dropout, 0, 1);
    m.get("porosity", &it->second.porosity, 0, 1);
    m.finish();
  }
  r.finish();
}

}  // namespace

static SimConfig readSimConfig(YamlReader r) {
  SimConfig c;
  c.source = r.origin();
  c.materials = defaultMaterials();
  r.get("name", &c.name);
  r.get("sensor", &c.sensor);
  r.get("frame_rate", &c.frame_rate, 0.5, 100);
  r.get("label_range", &c.label_range, 1, 500);
  r.get("label_min_points", &c.label_min_points, 0, 1000000);
  r.get("mount_height_jitter", &c.mount_height_jitter, 0, 0.5);
  r.get("mount_tilt_jitter_deg", &c.mount_tilt_jitter_deg, 0, 5);
  readRoad(r.child("road"), &c.road);
  readGround(r.child("ground"), &c.ground);
  readClutter(r.child("clutter"), &c.clutter);
  readTraffic(r.child("traffic"), &c.traffic);
  readMaterials(r.child("materials"), &c.materials);
  readPaint(r, &c.paint);
  r.finish();
  const TrafficConfig& t = c.traffic;
  if (t.sedan + t.hatchback + t.suv + t.van <= 0) r.fail("traffic.sedan", "body type mix sums to zero");
  return c;
}

SimConfig loadSimConfig(const std::string& path) { return readSimConfig(YamlReader::load(path)); }

}  // namespace sim
}  // namespace ret3d
